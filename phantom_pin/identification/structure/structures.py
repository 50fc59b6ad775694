"""The two structures ``estimate`` fits, each a set of physical parameters ``x`` (what the
overlay writes, then the six friction coefficients viscous1..3 in N m s/rad and coulomb1..3
in N m) and the base parameters the joint torques determine, beta = matrix x + offset:

- ``General``: the rigid body in full. x = the five bodies (config.types.BODIES) in
  standard parameters about their link frame's origin, Pinocchio's order [m (kg), m c
  (kg m), I_origin xx, xy, yy, xz, yz, zz (kg m^2)], then the rotor inertia J (kg m^2, at
  the motor shaft; absent without public motor data), then friction. beta: the base
  parameters of the mimic tree's regressor (base.base_parameters over seeded states: 26 for
  the Premium 1.5), every identifiable combination of mass, centre of mass, full inertia
  tensor and rotor inertia. Written as ``links.<body>.*`` keys: any model, in the report's
  form or in full, becomes a model in full (config.read).
- ``Report``: the report's structure (centres of mass on the segments' axes, the segment
  axes principal). x = parameterization.NAMES (20), then friction; beta = the report's
  eight constants (constants.NAMES) and friction. Written as the report's keys; only for a
  model in the report's form.

Each structure's physical check of x is the one of a link (phantom_pin.description.inertial.problem on
every link the overlay gives), with J > 0 for a model with a motor and friction >= 0.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from phantom_pin.config.types import BODIES
from phantom_pin.description.inertial import INERTIA_KEYS, Inertial, carve, problem, uncarve
from phantom_pin.dynamics.phantom import Phantom
from phantom_pin.exceptions import InvalidInputError
from phantom_pin.identification.structure import constants, parameterization, physical
from phantom_pin.identification.structure.base import base_parameters, sample, words
from phantom_pin.identification.structure.cache import cached
from phantom_pin.identification.structure.regressor import INERTIAL_NAMES, Regressor

FRICTION = constants.FRICTION_NAMES
#: The unit of each standard parameter (INERTIAL_NAMES order).
INERTIAL_UNITS = ("kg",) + ("kg m",) * 3 + ("kg m^2",) * 6



class Structured:
    """The regressor in the report parameters x and friction f: tau = Phi (x, f) + tau_0.

    Phi = [Y_rigid A, Y_friction] with pi = A x + b (parameterization.affine_map); tau_0 =
    Y_rigid b is the part fixed by the known parameters (zero here: the pins' compensation
    cancels and the base's fixed parameters do not enter). The configuration is the
    regressor's Phantom's (``description``).
    """

    def __init__(self, regressor: Regressor) -> None:
        self.regressor = regressor
        self.description = regressor.phantom.description
        self.affine, self.offset = parameterization.affine_map(self.description, regressor.bodies)
        self.offset[regressor.inertial] += regressor.carried  # a locked stylus gimbal: a known load
        self.names = tuple(parameterization.SYMBOLS) + tuple(
            f"{kind}{j}" for kind in ("viscous", "coulomb") for j in (1, 2, 3))

    def __call__(self, theta: object, dtheta: object, ddtheta: object) -> tuple[np.ndarray, np.ndarray]:
        """(Phi (..., 3, 26), tau_0 (..., 3)) at the given states (rad, rad/s, rad/s^2)."""
        y = self.regressor(theta, dtheta, ddtheta)
        rigid = y[..., :self.affine.shape[0]]
        return (np.concatenate([rigid @ self.affine, y[..., self.regressor.friction]], axis=-1),
                rigid @ self.offset)


#: A friction coefficient's typical size where the model has none, as a share of the joint's
#: torque limit (N m, and N m s/rad per rad/s): 1 %, near the shipped models' Coulomb friction
#: (0.01 N m against 0.33-0.38 N m) and far above what a joint's noise hides.
FRICTION_FLOOR = 0.01


class Structure:
    """Common part: the regressor of the Phantom, friction columns and the overlay's friction."""

    name = ""
    names: tuple[str, ...]            # x's
    base_names: tuple[str, ...]       # beta's, as sums of x's or of the regressor's parameters
    units: tuple[str, ...]            # beta's
    matrix: np.ndarray                # beta = matrix x + offset
    offset: np.ndarray
    prior: np.ndarray                 # x of the Phantom's own model (friction: its law, each joint)
    scale: np.ndarray                 # the typical size of each entry of x
    affine: np.ndarray                # the tree bodies' parameters pi = affine x + constant
    constant: np.ndarray
    rotor: int | None                 # x's index of the rotor inertia (None: no rotor parameter)

    def __init__(self, phantom: Phantom) -> None:
        self.phantom = phantom
        self.config = phantom.config
        self.regressor = Regressor(phantom)
        law = self.config.actuation.friction
        self.friction_prior = np.array([*law.viscous, *law.coulomb])    # each joint's own law
        # the friction coefficients' typical size: the model's, or where it is 0 (a model without
        # friction) FRICTION_FLOOR of the joint's torque limit (N m; per rad/s for viscous): a
        # zero size would drop the coefficient from the base parameters and the prior
        floor = FRICTION_FLOOR * np.tile(np.asarray(self.config.actuation.effort, dtype=float), 2)
        self.friction_scale = np.where(self.friction_prior > 0, self.friction_prior, floor)

    @property
    def motor(self) -> bool:
        return self.config.actuation.motor is not None

    def nearest(self, target: np.ndarray, weights: np.ndarray, prior_weight: float) -> np.ndarray:
        """physical.nearest: the consistent x whose base parameters are nearest to ``target`` in
        the metric W^T W (``weights``: the inverse covariance's root)."""
        n = len(self.names)
        # the links themselves must be physical (as ``consistent`` checks them), not the tree
        # bodies with a locked stylus gimbal's known load (regressor.carried) added
        links = self.constant.copy()
        links[self.regressor.inertial] -= self.regressor.carried
        bodies = [(self.affine[rows], links[rows]) for rows in
                  (slice(10 * k, 10 * k + 10) for k in range(len(self.regressor.bodies)))] + self.checked()
        rotor = [self.rotor] if self.rotor is not None else []
        positive = (rotor if self.motor else []) + list(range(n - 6, n))
        fixed = [] if self.motor or self.rotor is None else rotor
        start = self.prior.copy()      # strictly inside: a model without friction has it on the boundary
        start[n - 6:] = np.maximum(start[n - 6:], 1e-3 * self.friction_scale)
        return physical.nearest(target - self.offset, weights, self.matrix, start, self.scale, bodies,
                                positive, self.consistent, fixed, prior_weight)

    def checked(self) -> list[tuple[np.ndarray, np.ndarray]]:
        """The bodies ``consistent`` checks besides the tree's links, each as (A, b) with its
        standard parameters A x + b: nearest's barrier must hold them too, or its optimum (on
        the links' boundary) can leave one of them outside (issue 42, L14)."""
        return []

    def friction_ok(self, x: np.ndarray) -> bool:
        return bool((np.asarray(x)[-6:] >= 0).all())

    def regressor_of(self, theta: np.ndarray, dtheta: np.ndarray, ddtheta: np.ndarray,
                     friction: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """(Phi, tau_0) with tau = Phi x + tau_0 at the states (rad, rad/s, rad/s^2)."""
        raise NotImplementedError

    def consistent(self, x: np.ndarray) -> bool:
        """Whether x is physically consistent (every body passes inertial.problem)."""
        raise NotImplementedError

    def overrides(self, x: np.ndarray) -> dict[str, float]:
        """The --params keys of x (without friction)."""
        raise NotImplementedError


class General(Structure):
    """The rigid body in full (module doc)."""

    name = "general"

    def __init__(self, phantom: Phantom) -> None:
        super().__init__(phantom)
        description, regressor = phantom.description, self.regressor
        config, kinematics = self.config, self.config.kinematics
        prefix = description.prefix
        self.bodies = uncarve(config.links, kinematics)
        self.pin = config.links["crank_pin_link"]
        self.names = tuple(f"{b}.{p}" for b in BODIES for p in INERTIAL_NAMES) + (
            ("actuation.motor.rotor_inertia",) if self.motor else ()) + FRICTION
        n = len(self.names)
        a, b = self._affine_map(prefix, n)
        self.affine, self.constant = a, b
        self.rotor = 50 if self.motor else None
        self.prior = np.concatenate([*(self.bodies[name].dynamic_parameters() for name in BODIES),
                                     [config.actuation.rotor[0]] if self.motor else [], self.friction_prior])
        self.scale = np.concatenate([*(_body_scale(self.bodies[name]) for name in BODIES),
                                     [config.actuation.rotor[0]] if self.motor else [], self.friction_scale])
        base = cached(description, ("general base", prefix),   # the base of Y A: combinations of x only
                      lambda: base_parameters(regressor.stacked(*sample(regressor)), self.names, self.scale, a))
        order = np.argsort(base.independent)            # pivots in x's order: friction last
        self.base = dataclasses.replace(base, independent=tuple(base.independent[k] for k in order),
                                        matrix=base.matrix[order])
        self.independent = list(self.base.independent)
        self.matrix = self.base.matrix
        self.offset = np.zeros(self.base.rank)
        self.base_names = tuple(self.base.words(k) for k in range(self.base.rank))
        self.units = tuple(_unit(self.names[i]) for i in self.independent)
        self._friction_columns = [self.independent.index(i) for i in range(n - 6, n)]

    def _affine_map(self, prefix: str, n: int) -> tuple[np.ndarray, np.ndarray]:
        """(A, b) of pi (the regressor's parameters) = A x + b over the ``n`` parameters x: each
        tree link is its body less the pins' shares (constant: carve), the pins are fixed, the
        rotors J r^2."""
        regressor, config = self.regressor, self.config
        a, b = np.zeros((regressor.size, n)), np.zeros(regressor.size)
        b[regressor.inertial] = regressor.carried  # a locked stylus gimbal: a known load
        for k, link in enumerate(regressor.bodies):
            name, rows = link[len(prefix):], slice(10 * k, 10 * k + 10)
            if name in BODIES:
                i = BODIES.index(name)
                a[rows, 10 * i:10 * i + 10] = np.eye(10)
                b[rows] += config.links[name].dynamic_parameters() - self.bodies[name].dynamic_parameters()
            else:
                b[rows] += config.links[name].dynamic_parameters()
        if self.motor:
            a[regressor.rotors, 50] = np.square(np.asarray(config.actuation.ratios, dtype=float))
        a[regressor.friction, n - 6:] = np.eye(6)
        return a, b

    def regressor_of(self, theta, dtheta, ddtheta, friction=None) -> tuple[np.ndarray, np.ndarray]:
        """(Phi (N, 3, rank), tau_0 (N, 3)): the independent columns of the regressor in x,
        Y A, its friction columns replaced by ``friction`` (N, 3, 6) if given (estimation's
        filtered ones), and tau_0 = Y b, the torque of the known parameters (the hinge pins)."""
        y = self.regressor(theta, dtheta, ddtheta)
        phi = (y @ self.affine)[..., self.independent]
        if friction is not None:
            phi[..., self._friction_columns] = friction
        return phi, y @ self.constant

    def bodies_of(self, x: np.ndarray) -> dict[str, Inertial] | None:
        """The five bodies of ``x`` as the overlay writes them (None if a mass is not positive)."""
        x = np.asarray(x, float)
        if (x[0:50:10] <= 0).any():
            return None
        return {name: Inertial.from_dynamic_parameters(x[10 * i:10 * i + 10]) for i, name in enumerate(BODIES)}

    def checked(self) -> list[tuple[np.ndarray, np.ndarray]]:
        """The five bodies the overlay writes, x itself: a body is its tree link(s) plus the
        pins' shares, which for turret_link is a moment about z alone (carve), so a turret link
        on the triangle's edge leaves its body outside."""
        n = len(self.names)
        out = []
        for i in range(len(BODIES)):
            a = np.zeros((10, n))
            a[:, 10 * i:10 * i + 10] = np.eye(10)
            out.append((a, np.zeros(10)))
        return out

    def consistent(self, x: np.ndarray) -> bool:
        """Every body the overlay writes and every link carved from them passes the one physical
        check (config.read checks both), the rotor inertia is positive, friction >= 0."""
        bodies = self.bodies_of(x)
        if bodies is None or (self.motor and not x[50] > 0) or not self.friction_ok(x):
            return False
        links = carve(bodies, self.pin, self.config.kinematics)
        return all(problem(inertial) is None for inertial in (*bodies.values(), *links.values()))

    def overrides(self, x: np.ndarray) -> dict[str, float]:
        """The links.* keys (mass kg, com m, inertia about the com kg m^2) and the rotor inertia."""
        out: dict[str, float] = {}
        bodies = self.bodies_of(x)
        if bodies is None:
            raise InvalidInputError("a body's mass is not positive: no overlay", argument="x")
        for name, body in bodies.items():
            out[f"links.{name}.mass"] = body.mass
            out.update({f"links.{name}.com.{k}": v for k, v in enumerate(body.com)})
            out.update({f"links.{name}.inertia.{k}": v for k, v in zip(INERTIA_KEYS, body.inertia)})
        if self.motor:
            out["actuation.motor.rotor_inertia"] = float(x[50])
        return out


class Report(Structure):
    """The report's structure (module doc); InvalidInputError for a model in full."""

    name = "report"

    def __init__(self, phantom: Phantom) -> None:
        super().__init__(phantom)
        self.structured = Structured(self.regressor)
        description = phantom.description
        c = constants.constants_matrix(description)
        self.matrix = np.zeros((c.shape[0] + 6, c.shape[1] + 6))
        self.matrix[:c.shape[0], :c.shape[1]] = c
        self.matrix[c.shape[0]:, c.shape[1]:] = np.eye(6)
        self.offset = np.zeros(len(self.matrix))
        self.names = parameterization.NAMES + FRICTION
        self.base_names = tuple(f"{name} = {words(row, parameterization.SYMBOLS)}"
                                for name, row in zip(constants.NAMES, c)) + FRICTION
        self.units = constants.UNITS
        x0 = parameterization.report_vector(self.config)
        self.prior = np.concatenate([x0, self.friction_prior])
        self.scale = np.concatenate([np.where(x0 != 0, np.abs(x0), 1.0), self.friction_scale])
        self._pseudo = np.linalg.pinv(c)
        s = self.structured
        self.affine = np.hstack([s.affine, np.zeros((len(s.affine), 6))])
        self.constant = s.offset
        self.rotor = parameterization.ROTOR

    def regressor_of(self, theta, dtheta, ddtheta, friction=None) -> tuple[np.ndarray, np.ndarray]:
        """(Phi (N, 3, 14), tau_0 (N, 3)) in beta = (constants, friction), from Pinocchio's
        regressor: Phi = [Phi_x C^+, friction] (Phi_x = Y A, exact because Phi_x = Phi_constants
        C); ``friction`` (N, 3, 6) replaces the friction columns if given."""
        phi_x, tau0 = self.structured(theta, dtheta, ddtheta)
        n = len(parameterization.NAMES)
        friction = phi_x[..., n:] if friction is None else friction
        return np.concatenate([phi_x[..., :n] @ self._pseudo, friction], axis=-1), tau0

    def consistent(self, x: np.ndarray) -> bool:
        return self.friction_ok(x) and physical.consistent(x[:-6], self.config)

    def overrides(self, x: np.ndarray) -> dict[str, float]:
        return parameterization.overrides(x[:-6], self.config)


STRUCTURES = {"general": General, "report": Report}


def friction_block(columns: np.ndarray) -> np.ndarray:
    """The friction columns (N, 3, 6) that ``regressor_of`` takes, from per-sample values (N, 6):
    viscous1..3 then coulomb1..3, each on its own joint's row (diagonal blocks)."""
    return np.asarray(columns)[:, None, :] * np.tile(np.eye(3), 2)


def _unit(name: str) -> str:
    """The unit of one of General.names."""
    if name.startswith(("viscous", "coulomb")):
        return "N m s/rad" if name.startswith("viscous") else "N m"
    if name.endswith("rotor_inertia"):
        return "kg m^2"
    return INERTIAL_UNITS[INERTIAL_NAMES.index(name.rsplit(".", 1)[1])]


def _body_scale(body: Inertial) -> np.ndarray:
    """The typical size of a body's standard parameters: m, m r, m r^2 with r its radius of
    gyration about the link origin (m)."""
    pi = body.dynamic_parameters()
    m = pi[0]
    r = np.sqrt(max(pi[[4, 6, 9]].max(), 1e-12) / m)
    return np.array([m, *[m * r] * 3, *[m * r * r] * 6])


def main() -> None:
    regressor = Regressor(Phantom())
    states = sample(regressor)
    full = base_parameters(regressor.stacked(*states), regressor.names,
                           np.maximum(np.abs(regressor.parameters(5e-4, 0.01)), 1e-6))
    general = General(regressor.phantom)
    print(f"The mimic tree's regressor: {regressor.size} parameters ({len(regressor.bodies)} tree bodies x 10, "
          f"3 rotors, 6 friction), {full.rank} base parameters; two of them are the hinge pins' own first "
          "moments (crank_pin_link.mx, forearm_pin_link.mx), fixed by the model, so that the device has")
    print(f"General rigid-body model (identify's default): {len(general.names)} parameters (5 bodies x 10, "
          f"the rotor inertia, 6 friction), {general.base.rank} base parameters:")
    print("\n".join(general.base.describe()))
    structured = Structured(regressor)
    phi = structured(*states)[0].reshape(-1, len(structured.names))
    x0 = parameterization.report_vector(structured.description.config)
    report = base_parameters(phi, structured.names, np.concatenate([np.abs(x0), [5e-4] * 3 + [0.01] * 3]))
    print(f"\nThe report's structure: {len(structured.names)} parameters (report parameters and "
          f"friction), {report.rank} base parameters: the friction and the report's constants")
    for name, row in zip(constants.NAMES, constants.constants_matrix(structured.description)):
        print(f"{name:4} = {words(row, parameterization.SYMBOLS)}")


if __name__ == "__main__":
    main()
