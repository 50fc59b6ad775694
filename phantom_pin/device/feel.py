"""What the hand feels at the stylus: the device's own inertia and friction at the tip, the
largest force it renders there, and the workspace its stops allow (issue 52, item 1).

``feel(device, theta)`` returns a ``Feel`` of one posture. Frames and units: every vector is in
the report's frame s, whose axes are OpenHaptics' x (right), y (up), z (towards the user); tip
masses in g, forces in N, lengths in mm, the volume in cm^3. The measures are the rigid-body
model's and the friction law's of the configuration (config/NAME/*.yaml): they are what the
model predicts a hand would feel, not measurements of a device.
"""

from __future__ import annotations

import dataclasses
import math
import weakref
from typing import Any

import numpy as np

from phantom_pin._validation import as_state
from phantom_pin.config.types import STOP_COORDINATES
from phantom_pin.device.device import Device
from phantom_pin.exceptions import InvalidInputError

__all__ = ["Feel", "feel", "nominal_posture", "workspace_box", "workspace_volume", "SINGULAR_CONDITION",
           "DEFAULT_SPEED", "AXES"]

#: A posture whose tip Jacobian's condition number (2-norm) exceeds this is singular: the apparent
#: mass is unbounded along one direction there, and feel() refuses it rather than print a number.
SINGULAR_CONDITION = 1e8
#: The tip speed (m/s) of the sliding backdrive force unless another is given: a slow free-space
#: stroke of the hand.
DEFAULT_SPEED = 0.1
#: OpenHaptics' +x, -x, +y, -y, +z, -z (frame s's axes), the directions of the force limits.
AXES = np.vstack([np.eye(3)[[i, i]] * [[1.0], [-1.0]] for i in range(3)])
#: Gauss-Legendre nodes per piece of the workspace volume's quadrature (workspace_volume).
QUADRATURE_NODES = 48
#: Grid points per joint of the search that starts workspace_box's refinement.
BOX_GRID = 21
#: Each Device's workspace (box m, volume m^3), computed at its first feel(): the stops do not
#: change with the posture (a Device's Config is frozen).
_WORKSPACES: weakref.WeakKeyDictionary[Device, tuple[np.ndarray, np.ndarray, float]] = weakref.WeakKeyDictionary()


@dataclasses.dataclass(frozen=True)
class Feel:
    """The measures at one posture (frame s = OpenHaptics' axes; see the module's doc).

    - ``theta`` (3,) rad, the report's; ``posture``: its SRDF name ("zero") or "given";
      ``tip`` (3,) mm, the tip in frame s; ``condition``: the tip Jacobian's condition number.
    - Apparent mass, Lambda = (J M^-1 J^T)^-1 (J the tip's linear Jacobian in frame s,
      Device.tip_jacobian; M the joint-space mass matrix with the rotors, Phantom.mass_matrix):
      ``apparent_mass`` (3, 3) kg; ``principal_masses`` (3,) g, its eigenvalues, ascending, and
      ``directions`` (3, 3), their unit eigenvectors as columns; ``axis_masses`` (3,) g along x, y,
      z: m_u = 1 / (u^T Lambda^-1 u), the mass a hand feels accelerating the tip along u when it
      pushes along the motion's direction only (the tip's acceleration under a force F = f u has
      the component (u^T Lambda^-1 u) f along u).
    - Backdrive force (the friction law, config Friction, through the quasi-static relation
      F = J^-T tau_f, gravity held by the motors and inertia left out): moving the tip along
      +x, +y, +z (rows) needs the hand force ``breakaway`` (3, 3) N to start (each moving joint at
      its Coulomb torque; a joint whose rate is below 1e-12 of the largest does not move) and
      ``sliding`` (3, 3) N at ``speed`` m/s (plus the viscous torques); ``breakaway_along`` and
      ``sliding_along`` (3,) N are their components along the motion (the power they dissipate
      over the speed: u . F = tau_f . dtheta / |v|).
    - Force capacity: ``peak_force`` and ``continuous_force`` (6,) N, the largest tip force along
      AXES (+x, -x, +y, -y, +z, -z) within the peak and the continuous joint torques while
      holding gravity (Device.tip_force_capacity); inf where no joint is loaded. A model without
      public motor data (the Touch) has one limit for both. ``nominal_max_force`` (N) and
      ``nominal_max_stiffness`` (N/mm): actuation.yaml's openhaptics section (None without one).
    - Workspace the stops allow (the posture does not enter): ``box_lower``/``box_upper`` (3,) mm,
      the tip's extremes in frame s over every posture inside the stops (workspace_box), and
      ``volume`` cm^3 (workspace_volume).
    """

    model: str
    theta: np.ndarray
    posture: str
    tip: np.ndarray
    condition: float
    apparent_mass: np.ndarray
    principal_masses: np.ndarray
    directions: np.ndarray
    axis_masses: np.ndarray
    speed: float
    breakaway: np.ndarray
    breakaway_along: np.ndarray
    sliding: np.ndarray
    sliding_along: np.ndarray
    peak_force: np.ndarray
    continuous_force: np.ndarray
    nominal_max_force: float | None
    nominal_max_stiffness: float | None
    box_lower: np.ndarray
    box_upper: np.ndarray
    volume: float

    def as_dict(self) -> dict[str, Any]:
        """The measures as JSON-ready data (lists, floats; an unbounded force as None), with units."""
        data: dict[str, Any] = {}
        for field in dataclasses.fields(self):
            value = getattr(self, field.name)
            if isinstance(value, np.ndarray):
                value = np.where(np.isfinite(value), value, np.nan).tolist()
                value = _none_for_nan(value)
            data[field.name] = value
        data["units"] = {"theta": "rad", "tip": "mm, frame s", "apparent_mass": "kg", "principal_masses": "g",
                         "axis_masses": "g", "speed": "m/s", "breakaway": "N", "sliding": "N", "peak_force": "N",
                         "continuous_force": "N", "box_lower": "mm, frame s", "box_upper": "mm, frame s",
                         "volume": "cm^3", "nominal_max_stiffness": "N/mm"}
        return data


def _none_for_nan(value: Any) -> Any:
    if isinstance(value, list):
        return [_none_for_nan(v) for v in value]
    return None if isinstance(value, float) and math.isnan(value) else value


def nominal_posture(device: Device) -> tuple[np.ndarray, str]:
    """(theta, name) of the nominal posture: the SRDF's "zero", theta = (0, 0, 0) rad, where the
    upper arm is horizontal and the forearm vertical (the arms orthogonal) and the tip sits at frame
    s's origin, near the middle of the workspace: the "nominal position" at which the maximum force
    of a PHANToM is quoted (issue 52; the spec sheets' own definition was not reached, docs/feel.md)."""
    postures = device.config.limits.postures
    return np.array(postures.get("zero", (0.0, 0.0, 0.0)), dtype=float), "zero"


def _posture(device: Device, theta: object) -> tuple[np.ndarray, str]:
    if theta is None:
        return nominal_posture(device)
    q = as_state(theta, "theta")
    if not device.within_limits(q):
        raise InvalidInputError(f"{np.array2string(q, precision=6)} rad is outside the stops (Device.within_limits)",
                                argument="theta")
    return q, "given"


def feel(device: Device | None = None, theta: object = None, speed: float = DEFAULT_SPEED) -> Feel:
    """The measures of what the hand feels at posture ``theta`` (rad, the report's; default the
    nominal posture, nominal_posture: theta = 0, the arms orthogonal), with the
    sliding backdrive force at tip speed ``speed`` (m/s, > 0): a Feel (its doc gives each measure's
    definition, frame and unit). ``device``: a Device (default Device()).

    InvalidInputError naming ``theta`` for a posture outside the stops or a singular one (the tip
    Jacobian's condition number above SINGULAR_CONDITION: the apparent mass is unbounded there
    and the backdrive force undefined), naming ``speed`` for a speed that is not finite and > 0,
    naming ``device`` for anything but a Device."""
    device = Device() if device is None else device
    if not isinstance(device, Device):
        raise InvalidInputError(f"expected a phantom_pin.Device, got {device!r}", argument="device")
    if isinstance(speed, bool) or not isinstance(speed, (int, float)) or not 0 < speed < math.inf:
        raise InvalidInputError(f"expected a tip speed > 0 (m/s), got {speed!r}", argument="speed")
    q, posture = _posture(device, theta)
    jacobian = device.tip_jacobian(q)
    condition = float(np.linalg.cond(jacobian))
    if not condition < SINGULAR_CONDITION:
        raise InvalidInputError(f"{np.array2string(q, precision=6)} rad is singular (the tip Jacobian's condition "
                                f"number {condition:.3g}): the apparent mass is unbounded along one direction",
                                argument="theta")
    lam = _apparent_mass(device, q, jacobian)
    masses, directions = np.linalg.eigh(lam)
    axis_masses = 1.0 / np.diag(np.linalg.inv(lam))
    breakaway, sliding = _backdrive(device, jacobian, float(speed))
    openhaptics = device.config.actuation.openhaptics
    if device not in _WORKSPACES:
        _WORKSPACES[device] = (*workspace_box(device), workspace_volume(device))
    lower, upper, volume = _WORKSPACES[device]
    return Feel(model=device.config.name, theta=q, posture=posture,
                tip=device.phantom.forward_kinematics(q)[:3, 3] * 1e3, condition=condition,
                apparent_mass=lam, principal_masses=masses * 1e3, directions=directions,
                axis_masses=axis_masses * 1e3, speed=float(speed),
                breakaway=breakaway, breakaway_along=np.diag(breakaway).copy(),
                sliding=sliding, sliding_along=np.diag(sliding).copy(),
                peak_force=device.tip_force_capacity(np.tile(q, (6, 1)), AXES, continuous=False),
                continuous_force=device.tip_force_capacity(np.tile(q, (6, 1)), AXES, continuous=True),
                nominal_max_force=None if openhaptics is None else openhaptics.max_force,
                nominal_max_stiffness=None if openhaptics is None else openhaptics.max_stiffness,
                box_lower=lower * 1e3, box_upper=upper * 1e3, volume=volume * 1e6)


def _apparent_mass(device: Device, theta: np.ndarray, jacobian: np.ndarray) -> np.ndarray:
    """Lambda = (J M^-1 J^T)^-1 = J^-T M J^-1 (kg; J invertible here), symmetrised."""
    mass = device.phantom.mass_matrix(theta)
    inverse_j = np.linalg.inv(jacobian)
    lam = inverse_j.T @ mass @ inverse_j
    return 0.5 * (lam + lam.T)


def _backdrive(device: Device, jacobian: np.ndarray, speed: float) -> tuple[np.ndarray, np.ndarray]:
    """(breakaway, sliding) hand forces (3, 3) N, row k for the tip moving along axis k of frame s:
    F = J^-T tau_f with tau_f the friction torque of dtheta = J^-1 v (v = speed along the axis):
    the Coulomb torques alone (breakaway), and Friction.torque (sliding)."""
    law = device.config.actuation.friction
    rates = np.linalg.solve(jacobian, np.eye(3) * speed).T          # row k: dtheta for v = speed e_k
    # a joint the motion leaves still (to rounding) neither slides nor breaks away
    still = np.abs(rates) <= 1e-12 * np.abs(rates).max(axis=1, keepdims=True)
    rates = np.where(still, 0.0, rates)
    coulomb = np.asarray(law.coulomb) * np.sign(rates)
    sliding = law.torque(rates)
    to_force = np.linalg.inv(jacobian.T)
    return coulomb @ to_force.T, sliding @ to_force.T


def _stop_region(device: Device) -> tuple[np.ndarray, np.ndarray]:
    """(lower, upper) (4,) rad of the stop coordinates (STOP_COORDINATES: theta1..3, theta2 - theta3)."""
    return device.config.limits.stops.bounds()


def workspace_grid(device: Device) -> tuple[np.ndarray, np.ndarray]:
    """(postures (N, 3) rad, tips (N, 3) m in frame s) of a BOX_GRID^3 grid over the stops' region,
    the postures inside the stops: the tip's extremes over it bound the workspace box from inside
    (workspace_box refines them; the libHD stand-in reports them as they are)."""
    lower, upper = _stop_region(device)
    axes = [np.linspace(lower[i], upper[i], BOX_GRID) for i in range(3)]
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    grid = grid[device.within_limits(grid)]
    return grid, device.phantom.forward_kinematics(grid)[:, :3, 3]


def workspace_box(device: Device) -> tuple[np.ndarray, np.ndarray]:
    """(lower, upper) (3,) m: the tip's least and greatest x, y, z in frame s over every posture
    inside the stops (joint intervals and the parallelogram's coupled stops; the URDF's box plays
    no part). Each extreme: the best of workspace_grid's, refined by SLSQP on the stops' linear
    constraints with the tip Jacobian as gradient."""
    from scipy import optimize  # here: importing scipy.optimize costs every `import phantom_pin` 0.28 s

    lower, upper = _stop_region(device)
    grid, tips = workspace_grid(device)
    bounds = list(zip(lower[:3], upper[:3]))
    coupled = STOP_COORDINATES[3]
    constraints = [{"type": "ineq", "fun": lambda q: upper[3] - coupled @ q, "jac": lambda q: -coupled},
                   {"type": "ineq", "fun": lambda q: coupled @ q - lower[3], "jac": lambda q: coupled}]
    extremes = np.empty((2, 3))
    for k in range(3):
        for row, sign in enumerate((1.0, -1.0)):        # minimise, then maximise, coordinate k
            start = grid[np.argmin(sign * tips[:, k])]
            result = optimize.minimize(
                lambda q, k=k, s=sign: s * device.phantom.forward_kinematics(q)[k, 3], start,
                jac=lambda q, k=k, s=sign: s * device.tip_jacobian(q)[k], method="SLSQP", bounds=bounds,
                constraints=constraints, options={"ftol": 1e-14, "maxiter": 200})
            refined = np.clip(result.x, lower[:3], upper[:3])
            # SLSQP ends on an active coupled stop to within rounding; never further beyond it
            beyond = np.abs(device.config.limits.stops.penetration(refined)).max()
            best = refined if beyond < 1e-9 else start
            value = sign * device.phantom.forward_kinematics(best)[k, 3]
            extremes[row, k] = sign * min(value, (sign * tips[:, k]).min())
    return extremes[0], extremes[1]


def _gauss(a: float, b: float, n: int) -> tuple[np.ndarray, np.ndarray]:
    nodes, weights = np.polynomial.legendre.leggauss(n)
    half = 0.5 * (b - a)
    return a + half * (nodes + 1.0), half * weights


def workspace_volume(device: Device, nodes: int = QUADRATURE_NODES) -> float:
    """The volume (m^3) the tip sweeps over the postures inside the stops: the integral of
    |det J| over that region of joint space (J the tip Jacobian; the map is one-to-one there,
    which a Monte Carlo count of the points Device.reachable says the tip reaches confirms:
    tests/device/test_feel.py). det J does not depend on theta1 (a turn of frame s's vertical
    axis), so the integral is theta1's range times a 2-D integral over (theta2, theta3): the
    stops' polygon, cut where its edges change, each piece by Gauss-Legendre with ``nodes``
    points along theta2 and along theta3."""
    lower, upper = _stop_region(device)
    a2, b2, a3, b3 = lower[1], upper[1], lower[2], upper[2]
    below, above = upper[3], -lower[3]           # theta3 >= theta2 - below, theta3 <= theta2 + above
    cuts = sorted({a2, b2, *(c for c in (a3 + below, b3 - above, b3 + below, a3 - above) if a2 < c < b2)})
    points, weights = [], []
    for start, end in zip(cuts[:-1], cuts[1:]):
        t2, w2 = _gauss(start, end, nodes)
        for theta2, weight2 in zip(t2, w2):
            low, high = max(a3, theta2 - below), min(b3, theta2 + above)
            if high <= low:
                continue
            t3, w3 = _gauss(low, high, nodes)
            points.append(np.column_stack([np.zeros(nodes), np.full(nodes, theta2), t3]))
            weights.append(weight2 * w3)
    if not points:
        return 0.0
    q = np.concatenate(points)
    q[:, 0] = 0.5 * (lower[0] + upper[0])
    determinants = np.abs(np.linalg.det(device.tip_jacobian(q)))
    return float((upper[0] - lower[0]) * determinants @ np.concatenate(weights))
