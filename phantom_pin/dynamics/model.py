"""Phantom: the report's kinematics and dynamics, computed by Pinocchio on the URDF model."""

from __future__ import annotations

import itertools
import math
import os
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any, TypeGuard

import numpy as np
import pinocchio as pin

from phantom_pin.config import MODELS, Config
from phantom_pin.config.types import GIMBAL_JOINTS
from phantom_pin.description.build import Description, describe, description_of
from phantom_pin.description.gimbal import locked
from phantom_pin.dynamics.coupling import Coupling
from phantom_pin.dynamics.loader import gravity_of, load_rotor_parameters
from phantom_pin.exceptions import InvalidInputError, UnreachableTargetError
from phantom_pin.validation import as_states, finite_result, same_batch, within_box, wrap_angle

#: Newton iterations and position tolerance (m) of inverse_kinematics.
_IK_ITERATIONS, _IK_TOLERANCE = 60, 1e-13
#: Damping (m^2) of the normal equations: small enough that Newton still converges on the
#: shell's boundaries, where the Jacobian is singular (1e-12 stalled there near 6e-13 m).
_IK_DAMPING = 1e-16
#: Largest Newton step (rad); seeds (theta2, theta3 in rad) for each elbow branch.
_IK_MAX_STEP = 0.3
#: cos(theta3 - theta2) within this of 0 counts as either branch (the shell's boundaries).
_IK_BRANCH_SLACK = 1e-5
_IK_SEEDS = {"report": ((0.35, 0.3), (0.9, 1.0)), "other": ((-0.35, -2.8), (0.9, -1.5))}


_ONE = (3,)
#: eigenpy converts boolean arrays, which as_states refuses: the fast paths that check only
#: shapes send them to the checked path (a builtin dtype is one object)
_BOOL = np.dtype(bool)
_isfinite = math.isfinite


def _finite(array: np.ndarray) -> bool:
    """Cheap: True if ``array`` holds no NaN or inf (False also when its sum overflows,
    which only sends the caller to its slow path, where the full checks name the culprit)."""
    return math.isfinite(sum(array.ravel("K").tolist()))


def _one(value: object) -> TypeGuard[np.ndarray]:
    """The fast paths' check, written once: True if ``value`` is a finite vector of shape (3,)
    (an array; the dtype is left to eigenpy, but for booleans, which eigenpy would take: their
    tolist() gives bools, sent to the checked path, which refuses them by name).

    ``a, b, c = value.tolist() if value.size == 3 else ()`` then ``isfinite(a + b + c)`` is the
    cheapest check (0.16 us, against 0.33 us for a shape comparison and sum()): a batch fails
    to unpack () without being listed (ValueError), as tolist() of a (1, 3) array does; that of
    a (3, 1) array unpacks into lists whose sum isfinite refuses (TypeError), as it refuses
    complex numbers and strings; lists have no size (AttributeError). A sum that overflows only
    sends a finite input to the checked path. Functions of theta alone stay finite on a finite
    theta; where rates enter, whose products can overflow, the caller checks the result too."""
    try:
        a, b, c = value.tolist() if value.size == 3 else ()  # type: ignore[attr-defined,misc]
        return a.__class__ is not bool and _isfinite(a + b + c)
    except (AttributeError, TypeError, ValueError):
        return False


def _rows(function: Callable[..., np.ndarray], *arrays: np.ndarray, before: tuple = (),
          after: tuple = ()) -> np.ndarray:
    """``function(*before, *rows, *after)`` of each row of ``arrays`` (each (N, k)), stacked
    into one new array. map calls a Pinocchio function with its fixed arguments (model,
    data, frame...) in ``before`` and ``after`` without a Python frame per row."""
    fixed = map(itertools.repeat, before), map(itertools.repeat, after)
    return np.array(list(map(function, *fixed[0], *arrays, *fixed[1])))


def solve_spd(m: list[list[float]], r: Sequence[float]) -> tuple[float, float, float] | None:
    """x with m x = r for a symmetric 3x3 ``m`` (nested lists; the upper triangle is read),
    by its adjugate; None unless m is positive definite (Sylvester: leading minors > 0)."""
    (a, b, c), (_, d, e), (_, _, f) = m
    cof_a, cof_b, cof_c = d * f - e * e, c * e - b * f, b * e - c * d
    minor2, det = a * d - b * b, a * cof_a + b * cof_b + c * cof_c
    if not (a > 0 and minor2 > 0 and det > 0):
        return None
    cof_d, cof_e = a * f - c * c, b * c - a * e
    r0, r1, r2 = r
    return ((cof_a * r0 + cof_b * r1 + cof_c * r2) / det,
            (cof_b * r0 + cof_d * r1 + cof_e * r2) / det,
            (cof_c * r0 + cof_e * r1 + minor2 * r2) / det)


def _accelerations(mass: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """x with ``mass`` x = ``rhs`` (a symmetric (3, 3) M and (3,) torques): solve_spd, or where M
    is not positive definite (or not finite) Cholesky, which decides, as ever (LinAlgError)."""
    acc = solve_spd(mass.tolist(), rhs.tolist())
    if acc is None:
        factor = np.linalg.cholesky(mass)
        return np.linalg.solve(factor.T, np.linalg.solve(factor, rhs))
    return np.array(acc)


def _coriolis(coupling: Coupling, tree_data: pin.Data, q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """The Coriolis matrix of ``coupling``'s reduced model at (q, v): Pinocchio's is silently wrong
    on mimic models (DEVELOPERS.md), so the tree's, projected: C = G^T C_tree G."""
    return coupling.project(pin.computeCoriolisMatrix(coupling.tree, tree_data, coupling.configuration(q),
                                                      coupling.tangent(v)))


def _frame_jacobian(name: str, reference: pin.ReferenceFrame, doc: str) -> Callable[..., np.ndarray]:
    """A Phantom method: the tip's frame Jacobian in ``reference`` of the model rooted at
    frame s; a closure, so that its fast path is as short as forward_kinematics'."""
    def method(self: Phantom, theta: object) -> np.ndarray:
        model, data, tip = self._kinematics, self._kinematics_data, self._frame_tip
        if _one(theta):  # the fast path
            try:  # eigenpy refuses some dtypes (TypeError): the checked path converts them
                return pin.computeFrameJacobian(model, data, theta, tip, reference)
            except TypeError:
                pass
        return self._each(pin.computeFrameJacobian, ("theta",), theta, before=(model, data),
                          after=(tip, reference))
    method.__name__, method.__qualname__, method.__doc__ = name, f"Phantom.{name}", doc
    return method


def _rooted_at(source: pin.Model, world_to_s: pin.SE3) -> pin.Model:
    """A copy of ``source`` expressed in frame s: every placement on the world, joints' and
    frames', premultiplied by ``world_to_s`` (gravity rotated alike)."""
    model = source.copy()
    for jid in range(1, model.njoints):
        if model.parents[jid] == 0:
            model.jointPlacements[jid] = world_to_s * model.jointPlacements[jid]
    for frame in model.frames:
        if frame.parentJoint == 0:
            frame.placement = world_to_s * frame.placement
    model.gravity = world_to_s.act(model.gravity)
    return model


class Phantom:
    """The PHANToM in the report's coordinates, computed by Pinocchio.

    One input type per way of making it: ``Phantom()`` is the default model (premium_1_5, its
    committed URDF and SRDF), ``Phantom(name)`` another named model (phantom_pin.models()) and
    ``Phantom(description)`` a Description, the one result of reading a configuration
    (phantom_pin.describe(..., overrides=...)); the named constructors say the same explicitly:
    ``Phantom.from_model(name)``, ``Phantom.from_folder(path)`` (a configuration folder of
    one's own, generated by describe()) and ``Phantom.from_description(description)``. A
    folder given to the plain call is refused, naming from_folder.

    Joint vectors are the report's theta1..theta3 (rad), which are the URDF's
    joint1..joint3; rates in rad/s, accelerations in rad/s^2, torques in N m. Poses
    are in the report's kinematic frame s (URDF frame ``report_s``: x left, y up,
    z forward); the tool frame t is ``tip``. Every method takes one state, shape (3,),
    or a batch, shape (..., 3) (any number of leading axes, which each result keeps), of real
    numbers (booleans are refused), and returns fresh arrays.

    The stylus gimbal (a model with one: the Touch, ``config.gimbal``): its joints
    ``gimbal_joints`` (the URDF's joint4..joint6) are passive and their angles g, shape (3,)
    or (..., 3), are OpenHaptics' raw gimbal angles (rad). The arm's dynamics (every method of
    theta alone) carry the gimbal and stylus as a rigid load held at ``config.gimbal.locked_at``
    (gravity, mass_matrix, coriolis_matrix, inverse_dynamics and forward_dynamics take
    ``gimbal=`` to hold it at other angles); stylus_pose, stylus_tip_pose and stylus_jacobian
    use all six angles. The gimbal's angles broadcast against theta (one gimbal over a batch).

    Attributes: ``description`` (the Description it was built from), ``config`` (its
    typed configuration), ``model`` (the mimic model, nq = nv = 3, armature = the SRDF's
    rotor inertias times ratio^2; a gimbal locked), ``data``, ``coupling`` (the mimic-free
    tree model and the coupling matrix read from the URDF's mimic tags), ``gimbal_joints``
    (the gimbal's joint names, () without one), ``stylus_model`` (the six-joint mimic model
    rooted at frame s, or None), ``threads`` (OpenMP threads of batched inverse dynamics).
    """

    def __init__(self, source: Description | str | None = None) -> None:
        if not (source is None or isinstance(source, Description) or (isinstance(source, str) and source in MODELS)):
            raise InvalidInputError(f"expected a model name ({', '.join(MODELS)}), a Description or None, got "
                                    f"{source!r}; for a configuration folder use Phantom.from_folder(path)",
                                    argument="source")
        description = description_of(source, "source")
        self.description = description
        self.config: Config = description.config
        gimbal, prefix = self.config.gimbal, description.prefix
        self.gimbal_joints: tuple[str, ...] = () if gimbal is None else tuple(prefix + j for j in GIMBAL_JOINTS)
        self.coupling = Coupling(description.urdf if gimbal is None else
                                 locked(description.urdf, prefix, gimbal.locked_at))
        self.model: pin.Model = self.coupling.reduced
        for model in (self.model, self.coupling.tree):  # the configuration's g, along base_link's -z
            model.gravity = gravity_of(self.config)
        if self.config.actuation.motor is not None:  # else no rotor_params, armature 0 (Actuation.rotor)
            load_rotor_parameters(self.model, description.srdf)
        self.data = self.model.createData()
        self._tree_data = self.coupling.tree.createData()
        self._frame_s = self.model.getFrameId(prefix + "report_s")
        self._frame_tip = self.model.getFrameId(prefix + "tip")
        pin.framesForwardKinematics(self.model, self.data, pin.neutral(self.model))
        # report_s is fixed to the world: a copy of the model whose world is frame s gives
        # g_st and J^s directly (its joints' placements on the world premultiplied by g_s^-1)
        self._kinematics = self._rooted_at(self.data.oMf[self._frame_s].inverse())
        self._kinematics_data = self._kinematics.createData()
        self.threads = os.cpu_count() or 1
        self._pool: pin.ModelPool | None = None
        self.stylus_model: pin.Model | None = None
        self._frame_stylus = self._frame_stylus_tip = -1
        if gimbal is not None:  # the six-joint model, rooted at frame s as _kinematics
            #: the six joints' mimic model and its tree (the Coriolis matrix of the gimbal held, see
            #: coriolis_matrix), from the URDF with the gimbal free
            self._stylus_coupling = Coupling(description.urdf)
            self._stylus_tree_data = self._stylus_coupling.tree.createData()
            six = self._stylus_coupling.reduced
            six.gravity = gravity_of(self.config)
            six_data = six.createData()
            pin.framesForwardKinematics(six, six_data, pin.neutral(six))
            self.stylus_model = _rooted_at(six, six_data.oMf[six.getFrameId(prefix + "report_s")].inverse())
            names = (*(f"{prefix}joint{j}" for j in (1, 2, 3)), *self.gimbal_joints)
            #: the six-joint model's q (and, every joint revolute, v) of (theta, g): q[order] = (theta1..3, g1..3)
            self._order = np.array([self.stylus_model.joints[self.stylus_model.getJointId(n)].idx_q for n in names])
            self._arm, self._arm_block = self._order[:3], np.ix_(self._order[:3], self._order[:3])
            armature = self.stylus_model.armature.copy()
            armature[self._arm] = self.model.armature  # the rotors, as the arm's model has them
            self.stylus_model.armature = armature
            self._stylus_data = self.stylus_model.createData()
            self._frame_stylus = self.stylus_model.getFrameId(f"{prefix}stylus")
            self._frame_stylus_tip = self.stylus_model.getFrameId(f"{prefix}stylus_tip")

    @classmethod
    def from_model(cls, name: str) -> Phantom:
        """The named model ``name`` (phantom_pin.models()), from its committed files."""
        if not (isinstance(name, str) and name in MODELS):
            raise InvalidInputError(f"expected one of {', '.join(MODELS)}, got {name!r}", argument="name")
        return cls(name)

    @classmethod
    def from_folder(cls, folder: str | Path) -> Phantom:
        """A configuration folder of one's own (its YAML files), through phantom_pin.describe."""
        return cls(describe(folder))

    @classmethod
    def from_description(cls, description: Description) -> Phantom:
        """A Description (phantom_pin.describe, with overrides)."""
        if not isinstance(description, Description):
            raise InvalidInputError(f"expected a phantom_pin.Description, got {description!r}", argument="description")
        return cls(description)

    # -- helpers ---------------------------------------------------------------------
    def _rooted_at(self, world_to_s: pin.SE3) -> pin.Model:
        return _rooted_at(self.model, world_to_s)

    @staticmethod
    def _states(names: tuple[str, ...], *values: object) -> list[np.ndarray]:
        arrays = [as_states(v, n)[0] for n, v in zip(names, values)]
        same_batch(names, *arrays)
        return arrays

    @classmethod
    def _each(cls, function: Callable[..., np.ndarray], names: tuple[str, ...],
              *values: object, before: tuple = (), after: tuple = ()) -> np.ndarray:
        """Check ``values`` (named ``names``) and apply ``function(*before, *states,
        *after)`` over their leading axes; raise InvalidInputError naming them if the
        result is not finite."""
        arrays = cls._states(names, *values)
        if arrays[0].ndim == 1:
            return finite_result(function(*before, *arrays, *after), ", ".join(names))
        out = _rows(function, *(a.reshape(-1, a.shape[-1]) for a in arrays), before=before, after=after)
        return finite_result(out.reshape(arrays[0].shape[:-1] + out.shape[1:]), ", ".join(names))

    def _tree_batch(self, function: Callable[..., np.ndarray], names: tuple[str, ...],
                    theta: np.ndarray, *rates: np.ndarray, before: tuple = ()) -> np.ndarray:
        """``function(*before, q, *rates)`` of tree configurations and tangents over checked
        states, (3,) or (..., 3): the coupling maps the whole batch, Pinocchio runs per row,
        the results (N, ..., tree.nv, tree.nv) are projected at once; checked for
        finiteness (an overflow is reported by finite_result, not by NumPy's warnings)."""
        coupling = self.coupling
        with np.errstate(invalid="ignore", over="ignore"):
            tree = _rows(function, coupling.configuration(theta.reshape(-1, 3)),
                         *(coupling.tangent(r.reshape(-1, 3)) for r in rates), before=before)
            out = coupling.project(tree)
        return finite_result(out.reshape(theta.shape[:-1] + out.shape[1:]), ", ".join(names))

    def within_limits(self, theta: object) -> bool | np.ndarray:
        """True where ``theta`` (rad), shape (3,) or (..., 3), lies inside the URDF's box
        joint limits (``model.lowerPositionLimit`` <= theta <= ``upperPositionLimit``,
        bounds included): a bool for one state, a bool array of shape (...) for a batch.

        Every method computes outside the limits too (the model is valid there); ask
        this to flag such states. The physical device's stops, coupled ones included,
        are narrower or wider per joint and are not these.
        """
        return within_box(theta, self.model.lowerPositionLimit, self.model.upperPositionLimit)

    def _pose(self, theta: np.ndarray) -> np.ndarray:
        """g_st (4, 4) at theta: the tip's placement in the model rooted at frame s."""
        pin.forwardKinematics(self._kinematics, self._kinematics_data, theta)
        return pin.updateFramePlacement(self._kinematics, self._kinematics_data,
                                        self._frame_tip).homogeneous

    def _batched(self, theta: np.ndarray, dtheta: np.ndarray, ddtheta: np.ndarray) -> np.ndarray:
        """rneaInParallel over checked (..., 3) arrays: tau, shape (..., 3), not yet checked."""
        if self._pool is None or self._pool.size() < self.threads:
            self._pool = pin.ModelPool(self.model, self.threads)
        shape = theta.shape
        tau = np.empty((3, math.prod(shape[:-1])), order="F")
        pin.rneaInParallel(self.threads, self._pool, theta.reshape(-1, 3).T,
                           dtheta.reshape(-1, 3).T, ddtheta.reshape(-1, 3).T, tau)
        return tau.T.reshape(shape)

    # -- kinematics ------------------------------------------------------------------
    def forward_kinematics(self, theta: object) -> np.ndarray:
        """Pose g_st of the tool frame t in frame s (eq. 10): shape (..., 4, 4), metres."""
        if _one(theta):  # the fast path
            try:  # eigenpy refuses some dtypes (TypeError): the checked path converts them
                pin.forwardKinematics(self._kinematics, self._kinematics_data, theta)
                return pin.updateFramePlacement(self._kinematics, self._kinematics_data, self._frame_tip).homogeneous
            except TypeError:
                pass
        return self._each(self._pose, ("theta",), theta)

    def inverse_kinematics(self, position: object, branch: str = "report") -> np.ndarray:
        """Joint angles (rad) that put the tip at ``position`` (m, frame s).

        Damped Newton iterations on Pinocchio's forward kinematics and frame Jacobian,
        seeded on the requested elbow branch ("report": the report's gamma > 0,
        alpha > 0, the branch the parallelogram reaches; "other": the mirrored elbow).
        Raises UnreachableTargetError outside the reachable shell
        |l1 - l2| <= distance from the shoulder <= l1 + l2. Angles are wrapped into
        (-pi, pi], as closed_form.inverse_kinematics returns them (theta1 = +pi behind
        the shoulder). The result may lie outside the joint limits: see within_limits.
        """
        if branch not in _IK_SEEDS:
            raise InvalidInputError(f"branch: expected 'report' or 'other', got {branch!r}")
        return self._each(lambda p: self._solve_ik(p, branch), ("position",), position)

    def _solve_ik(self, target: np.ndarray, branch: str) -> np.ndarray:
        p = self.config.kinematics
        x, y, z = target.tolist()
        distance = math.hypot(x, y - p.l2, z + p.l1)  # from the shoulder (0, l2, -l1) in s
        if not abs(p.l1 - p.l2) * (1 - 1e-12) <= distance <= (p.l1 + p.l2) * (1 + 1e-12):
            raise UnreachableTargetError(
                f"position: {np.array2string(target, precision=4)} m is {distance:.4g} m from "
                f"the shoulder, outside the reachable shell [{abs(p.l1 - p.l2):.4f}, "
                f"{p.l1 + p.l2:.4f}] m")
        sign = 1.0 if branch == "report" else -1.0
        for seed in _IK_SEEDS[branch]:
            theta = self._newton((x, y, z), np.array([math.atan2(x, z + p.l1), *seed]))
            # the report's branch has the elbow open forwards, cos(theta3 - theta2) =
            # sin(alpha) >= 0; on the shell's boundaries (alpha = 0 or pi) both branches
            # meet, where Newton's angles are good to about sqrt(tolerance / l) ~ 1e-6 rad
            if theta is not None and sign * math.cos(theta[2] - theta[1]) > -_IK_BRANCH_SLACK:
                return wrap_angle(theta)
        raise UnreachableTargetError(
            f"position: no {branch}-branch solution found for {target} m")

    def _newton(self, target: tuple[float, float, float], theta: np.ndarray) -> np.ndarray | None:
        """Damped Newton on the tip position from ``theta``; None if it does not converge.

        Each step solves the damped normal equations (J^T J + damping I) step = J^T error,
        J the tip point's (3, 3) Jacobian in s; in floats, which is 2x faster than NumPy on
        3-vectors."""
        model, data, tip = self._kinematics, self._kinematics_data, self._frame_tip
        tx, ty, tz = target
        for _ in range(_IK_ITERATIONS):
            # rows 0-2 of the LOCAL_WORLD_ALIGNED Jacobian: the tip point's velocity in s;
            # its columns a, b, c, one per joint
            jacobian = pin.computeFrameJacobian(model, data, theta, tip, pin.LOCAL_WORLD_ALIGNED)
            (a0, b0, c0), (a1, b1, c1), (a2, b2, c2) = jacobian[:3].tolist()
            x, y, z = data.oMf[tip].translation.tolist()
            ex, ey, ez = tx - x, ty - y, tz - z
            if math.hypot(ex, ey, ez) < _IK_TOLERANCE:
                return theta
            ab = a0 * b0 + a1 * b1 + a2 * b2
            ac = a0 * c0 + a1 * c1 + a2 * c2
            bc = b0 * c0 + b1 * c1 + b2 * c2
            normal = [[a0 * a0 + a1 * a1 + a2 * a2 + _IK_DAMPING, ab, ac],
                      [ab, b0 * b0 + b1 * b1 + b2 * b2 + _IK_DAMPING, bc],
                      [ac, bc, c0 * c0 + c1 * c1 + c2 * c2 + _IK_DAMPING]]
            gradient = (a0 * ex + a1 * ey + a2 * ez, b0 * ex + b1 * ey + b2 * ez,
                        c0 * ex + c1 * ey + c2 * ez)
            step = solve_spd(normal, gradient)
            if step is None:  # singular to rounding: LAPACK's LU, as before the float path
                step = np.linalg.solve(np.array(normal), gradient).tolist()
            largest = max(map(abs, step))
            scale = 1.0 if largest <= _IK_MAX_STEP else _IK_MAX_STEP / largest
            t0, t1, t2 = theta.tolist()
            theta = np.array([t0 + scale * step[0], t1 + scale * step[1], t2 + scale * step[2]])
        return None

    # -- the stylus (a model with a gimbal) ----------------------------------------------
    def _stylus(self) -> tuple[pin.Model, pin.Data]:
        if self.stylus_model is None:
            raise InvalidInputError(f"the model {self.config.name!r} has no stylus gimbal (config.gimbal is None: "
                                    "only a model whose gimbal is public, the Touch, has one)", argument="gimbal")
        return self.stylus_model, self._stylus_data

    def _six(self, names: tuple[str, ...], gimbal: object, *values: object) -> list[np.ndarray]:
        """The six-joint model's arrays (..., 6) of the arm's ``values`` (named ``names``, of one
        shape; the first theta (rad), with the gimbal angles ``gimbal`` (rad); the others, rates,
        accelerations or torques, with the gimbal's zero), checked, over the batch shape that
        theta's and the gimbal's broadcast to (NumPy's rules: one gimbal over a batch of theta)."""
        self._stylus()
        arm = self._states(names, *values)
        g, _ = as_states(gimbal, "gimbal")
        try:
            shape = np.broadcast_shapes(arm[0].shape[:-1], g.shape[:-1])
        except ValueError:
            raise InvalidInputError(f"shape {g.shape} does not broadcast against {names[0]}'s {arm[0].shape}",
                                    argument="gimbal") from None
        six = [np.zeros(shape + (6,)) for _ in arm]
        for out, value in zip(six, arm):
            out[..., self._arm] = value
        six[0][..., self._order[3:]] = g
        return six

    def _one_six(self, theta: np.ndarray, gimbal: np.ndarray | None) -> np.ndarray:
        """The six-joint model's q of one finite (theta, gimbal) (the fast paths); with ``gimbal``
        None, a rate's, acceleration's or torque's (the gimbal's zero)."""
        q = np.zeros(6)
        q[self._arm] = theta
        if gimbal is not None:
            q[self._order[3:]] = gimbal
        return q

    def _held(self, one: Callable[..., np.ndarray], names: tuple[str, ...], gimbal: object,
              *values: object) -> np.ndarray:
        """The arm's dynamics with the stylus gimbal held at ``gimbal`` (rad; its rates and
        accelerations zero), every method's one path: ``one(q, *others)`` of the six-joint
        model's arrays of theta (``values[0]``) with the gimbal and of the arm's other ``values``
        (_six), one state or over the broadcast batch; InvalidInputError naming ``names`` and
        ``gimbal`` for a bad argument or a result that is not finite."""
        arm: Any = values  # finite vectors (3,) once _one says so
        if self.stylus_model is not None and _one(gimbal) and all(map(_one, arm)):  # the fast path
            try:  # eigenpy refuses some dtypes (TypeError): the checked path converts them
                out = one(self._one_six(arm[0], gimbal), *(self._one_six(v, None) for v in arm[1:]))
                if _finite(out):  # rates can overflow
                    return out
            except TypeError:
                pass
        arrays = self._six(names, gimbal, *values)
        with np.errstate(invalid="ignore", over="ignore"):  # reported by finite_result
            out = _rows(one, *(a.reshape(-1, 6) for a in arrays))
        return finite_result(out.reshape(arrays[0].shape[:-1] + out.shape[1:]), ", ".join((*names, "gimbal")))

    # the arm's rows (and columns) of the six-joint model's dynamics at one state, for _held
    def _held_gravity(self, q: np.ndarray) -> np.ndarray:
        return pin.computeGeneralizedGravity(self.stylus_model, self._stylus_data, q)[self._arm]

    def _held_mass(self, q: np.ndarray) -> np.ndarray:
        return pin.crba(self.stylus_model, self._stylus_data, q)[self._arm_block]  # the full matrix, as mass_matrix's

    def _held_coriolis(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        return _coriolis(self._stylus_coupling, self._stylus_tree_data, q, v)[self._arm_block]

    def _held_torques(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
        return pin.rnea(self.stylus_model, self._stylus_data, q, v, a)[self._arm]

    def _held_forward(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        model, data, arm = self.stylus_model, self._stylus_data, self._arm
        return _accelerations(pin.crba(model, data, q)[self._arm_block],
                              tau[arm] - pin.nonLinearEffects(model, data, q, v)[arm])

    def _stylus_frame(self, frame: int, theta: object, gimbal: object, jacobian: bool = False) -> np.ndarray:
        model = self.stylus_model
        if _one(theta) and _one(gimbal) and model is not None and not jacobian:  # the fast path
            try:
                pin.forwardKinematics(model, self._stylus_data, self._one_six(theta, gimbal))
                return pin.updateFramePlacement(model, self._stylus_data, frame).homogeneous
            except TypeError:
                pass
        (q,) = self._six(("theta",), gimbal, theta)
        model, data = self._stylus()

        def one(configuration: np.ndarray) -> np.ndarray:
            if jacobian:  # columns in (theta, g) order
                return pin.computeFrameJacobian(model, data, configuration, frame, pin.WORLD)[:, self._order]
            pin.forwardKinematics(model, data, configuration)
            return pin.updateFramePlacement(model, data, frame).homogeneous

        out = np.array([one(c) for c in q.reshape(-1, 6)])
        return finite_result(out.reshape(q.shape[:-1] + out.shape[1:]), "theta, gimbal")

    def stylus_pose(self, theta: object, gimbal: object) -> np.ndarray:
        """Pose of the stylus frame in frame s: (..., 4, 4), metres. Its origin is the gimbal
        centre (the tip of eq. 10), its rotation Ry(theta1) Rx(-theta3) Ry(g1) Rx(-g2) Rz(-g3)
        (report axes; Ubitrack's stylus rotation of OpenHaptics' angles), +z along the stylus
        towards its back end. ``theta`` (rad) and ``gimbal`` (OpenHaptics' raw gimbal angles,
        rad), each (3,) or (..., 3). InvalidInputError naming ``gimbal`` for a model without one."""
        return self._stylus_frame(self._frame_stylus, theta, gimbal)

    def stylus_tip_pose(self, theta: object, gimbal: object) -> np.ndarray:
        """Pose of the stylus tip in frame s: the stylus frame moved ``config.gimbal.tip_offset``
        along its -z: (..., 4, 4), metres."""
        return self._stylus_frame(self._frame_stylus_tip, theta, gimbal)

    def stylus_jacobian(self, theta: object, gimbal: object) -> np.ndarray:
        """Spatial Jacobian of the stylus frame in frame s (as spatial_jacobian, eq. 22):
        (..., 6, 6), the twist (v, omega) in frame s (m/s, rad/s) per unit rate of (theta1..3,
        g1..g3) (rad/s)."""
        return self._stylus_frame(self._frame_stylus, theta, gimbal, jacobian=True)

    spatial_jacobian = _frame_jacobian("spatial_jacobian", pin.WORLD, """Spatial Jacobian J^s (eq. 22): (..., 6, 3),
        twist (v, omega) in frame s.

        Pinocchio's WORLD frame Jacobian of ``tip`` in the model rooted at frame s.
        """)
    body_jacobian = _frame_jacobian("body_jacobian", pin.LOCAL, """Body Jacobian J^b (eq. 24): (..., 6, 3),
        twist (v, omega) in the tool frame t.""")

    # -- dynamics --------------------------------------------------------------------
    def mass_matrix(self, theta: object, gimbal: object = None) -> np.ndarray:
        """Joint-space inertia M(theta) (eqs 81-85), with the rotors' armature: (..., 3, 3),
        kg m^2. ``gimbal`` (rad, a model with a gimbal only): held at those angles instead of at
        ``locked_at``, as in gravity."""
        if gimbal is not None:
            return self._held(self._held_mass, ("theta",), gimbal, theta)
        if _one(theta):  # the fast path
            try:  # eigenpy refuses some dtypes (TypeError): the checked path converts them
                return pin.crba(self.model, self.data, theta)
            except TypeError:
                pass
        # the binding of crba returns the full symmetric matrix (DEVELOPERS.md), not data.M
        return self._each(pin.crba, ("theta",), theta, before=(self.model, self.data))

    def coriolis_matrix(self, theta: object, dtheta: object, gimbal: object = None) -> np.ndarray:
        """Coriolis matrix C(theta, dtheta) (eqs 86-92): (..., 3, 3), N m s/rad.

        Pinocchio's computeCoriolisMatrix is silently wrong on mimic models, so it runs
        on the tree model and is projected: C = G^T C_tree G. ``gimbal`` (rad): held at those
        angles, as in gravity: the arm's block of the six-joint model's C at zero gimbal rates
        (its Christoffel symbols over the arm's coordinates: those of the arm locked there).
        """
        if gimbal is not None:
            return self._held(self._held_coriolis, ("theta", "dtheta"), gimbal, theta, dtheta)
        if _one(theta) and _one(dtheta):  # the fast path; rates can overflow C
            try:  # eigenpy refuses some dtypes (TypeError): the checked path converts them
                out = _coriolis(self.coupling, self._tree_data, theta, dtheta)
                if _finite(out):
                    return out
            except TypeError:
                pass
        names = ("theta", "dtheta")
        return self._tree_batch(pin.computeCoriolisMatrix, names, *self._states(names, theta, dtheta),
                                before=(self.coupling.tree, self._tree_data))

    def gravity(self, theta: object, gimbal: object = None) -> np.ndarray:
        """Gravity torque N(theta) (eqs 93-94): (..., 3), N m.

        A batch: rnea at zero rates and accelerations, by rneaInParallel. ``gimbal`` (rad,
        (3,) or (..., 3), broadcast against theta; a model with a gimbal only, else
        InvalidInputError naming it): the torques that hold the arm with the stylus at those
        gimbal angles (the arm's rows of the six-joint model's gravity: the passive gimbal's own
        torques are the hand's), instead of at ``locked_at``. mass_matrix, coriolis_matrix,
        inverse_dynamics and forward_dynamics take ``gimbal`` alike (the gimbal held at those
        angles: its rates and accelerations zero), each through one path (_held).
        """
        if gimbal is not None:
            return self._held(self._held_gravity, ("theta",), gimbal, theta)
        if _one(theta):  # the fast path
            try:  # eigenpy refuses some dtypes (TypeError): the checked path converts them
                return pin.computeGeneralizedGravity(self.model, self.data, theta)
            except TypeError:
                pass
        (q,) = self._states(("theta",), theta)
        if q.ndim == 1:
            return finite_result(pin.computeGeneralizedGravity(self.model, self.data, q), "theta")
        zero = np.zeros_like(q)
        return finite_result(self._batched(q, zero, zero), "theta")

    def potential_energy(self, theta: object) -> np.ndarray:
        """Potential energy V(theta) (J), zero with every centre of mass at shoulder height:
        shape (...) (a 0-d array for one state). On the tree model: the coupling maps the
        whole batch, Pinocchio runs per row."""
        (q,) = self._states(("theta",), theta)
        energy = _rows(pin.computePotentialEnergy, self.coupling.configuration(q.reshape(-1, 3)),
                       before=(self.coupling.tree, self._tree_data))
        return energy.reshape(q.shape[:-1])  # finite: V is a sum of masses times heights

    def inverse_dynamics(self, theta: object, dtheta: object, ddtheta: object, gimbal: object = None) -> np.ndarray:
        """Joint torques tau = M ddtheta + C dtheta + N (eq. 80): (..., 3), N m.

        One state: pinocchio.rnea on the mimic model. A batch (..., 3):
        pinocchio.rneaInParallel over ``threads`` OpenMP threads. ``gimbal`` (rad): held at
        those angles, as in gravity (the arm's rows of the six-joint model's rnea).
        """
        if gimbal is not None:
            return self._held(self._held_torques, ("theta", "dtheta", "ddtheta"), gimbal, theta, dtheta, ddtheta)
        q: Any = theta  # any object: its shape is asked, not assumed (lists have none)
        try:  # the fast path: one state (3,); eigenpy refuses (TypeError) complex and object
            if (q.shape == dtheta.shape == ddtheta.shape == _ONE  # type: ignore[attr-defined]
                    and _BOOL is not q.dtype and _BOOL is not dtheta.dtype  # type: ignore[attr-defined]
                    and _BOOL is not ddtheta.dtype):  # type: ignore[attr-defined]
                tau = pin.rnea(self.model, self.data, theta, dtheta, ddtheta)  # (a fresh array)
                # NaN/inf in any input, or an overflow, reaches tau (tests/test_fast_paths.py);
                # only then are the inputs inspected, to name the bad one.
                t0, t1, t2 = tau.tolist()
                if _isfinite(t0 + t1 + t2):
                    return tau
        except (AttributeError, TypeError):  # no shape (lists), or not for eigenpy
            pass
        names = ("theta", "dtheta", "ddtheta")
        q, v, a = self._states(names, theta, dtheta, ddtheta)
        if q.ndim == 1:
            return finite_result(pin.rnea(self.model, self.data, q, v, a), ", ".join(names))
        return finite_result(self._batched(q, v, a), ", ".join(names))

    def _forward(self, theta: np.ndarray, dtheta: np.ndarray, tau: np.ndarray) -> np.ndarray:
        return _accelerations(pin.crba(self.model, self.data, theta),
                              tau - pin.nonLinearEffects(self.model, self.data, theta, dtheta))

    def forward_dynamics(self, theta: object, dtheta: object, tau: object, gimbal: object = None) -> np.ndarray:
        """Joint accelerations (rad/s^2) under torques ``tau`` (N m): M^-1 (tau - C dtheta - N).

        pinocchio.aba refuses mimic models, so M (crba) and the bias torques
        (nonLinearEffects) come from Pinocchio and the symmetric 3x3 system is solved by
        its adjugate; np.linalg.cholesky raises LinAlgError if M is not positive definite.
        A batch: the bias torques by rneaInParallel, M per state, one batched solve.
        ``gimbal`` (rad): held at those angles, as in gravity (the arm's block of the six-joint
        model's M and its rows of the bias torques), one state at a time.
        """
        if gimbal is not None:
            return self._held(self._held_forward, ("theta", "dtheta", "tau"), gimbal, theta, dtheta, tau)
        rates: Any = dtheta  # any object: its shape is asked, not assumed
        torques: Any = tau
        # the fast path: NaN/inf in dtheta or tau reaches every acceleration (0 * NaN is NaN),
        # so the result is checked; theta1 enters neither M nor the bias torques, so theta is
        # checked first. A tau of shape (3, 1) unpacks into lists, whose difference with a float
        # raises TypeError.
        if _one(theta):
            try:
                t0, t1, t2 = torques.tolist()
                if rates.shape == _ONE and t0.__class__ is not bool and rates.dtype is not _BOOL:
                    model, data = self.model, self.data
                    bias = pin.nonLinearEffects(model, data, theta, dtheta).tolist()
                    acc = solve_spd(pin.crba(model, data, theta).tolist(),
                                    (t0 - bias[0], t1 - bias[1], t2 - bias[2]))
                    if acc is not None and _isfinite(sum(acc)):  # rates can overflow
                        return np.array(acc)
            except (AttributeError, TypeError, ValueError):  # no shape, not for eigenpy, complex tau
                pass
        names = ("theta", "dtheta", "tau")
        q, v, torque = self._states(names, theta, dtheta, tau)
        if q.ndim == 1:
            return finite_result(self._forward(q, v, torque), ", ".join(names))
        with np.errstate(invalid="ignore", over="ignore"):  # reported by finite_result
            rhs = torque - self._batched(q, v, np.zeros_like(q))
        mass = _rows(pin.crba, q.reshape(-1, 3), before=(self.model, self.data)).reshape(q.shape + (3,))
        np.linalg.cholesky(mass)  # LinAlgError unless every M is positive definite
        accelerations = np.linalg.solve(mass, rhs[..., None])[..., 0]
        return finite_result(accelerations, ", ".join(names))

    def _tree_derivatives(self, theta: np.ndarray, dtheta: np.ndarray, ddtheta: np.ndarray) -> np.ndarray:
        """d tau_tree / d q and d tau_tree / d v of the tree model, (2, tree.nv, tree.nv)."""
        return np.array(pin.computeRNEADerivatives(self.coupling.tree, self._tree_data, theta,
                                                   dtheta, ddtheta)[:2])

    def inverse_dynamics_derivatives(self, theta: object, dtheta: object,
                                     ddtheta: object) -> tuple[np.ndarray, np.ndarray]:
        """(d tau / d theta, d tau / d dtheta), each (..., 3, 3), in N m/rad and N m s/rad.

        Pinocchio's RNEA derivatives refuse mimic models; they run on the tree model
        and are projected: d tau/d theta = G^T (d tau_tree/d q) G, and likewise for dtheta.
        """
        coupling = self.coupling
        if _one(theta) and _one(dtheta) and _one(ddtheta):  # the fast path; rates can overflow
            try:  # eigenpy refuses some dtypes (TypeError): the checked path converts them
                both = coupling.project(self._tree_derivatives(
                    coupling.configuration(theta), coupling.tangent(dtheta), coupling.tangent(ddtheta)))
                if _finite(both):
                    return both[0], both[1]
            except TypeError:
                pass
        names = ("theta", "dtheta", "ddtheta")
        both = self._tree_batch(self._tree_derivatives, names, *self._states(names, theta, dtheta, ddtheta))
        return both[..., 0, :, :].copy(), both[..., 1, :, :].copy()
