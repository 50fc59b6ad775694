"""Phantom: the report's kinematics and dynamics, computed by Pinocchio on the URDF model."""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin

from phantom_pin._validation import as_states, finite_result, same_batch, within_box
from phantom_pin.config import MODELS, Config, renamed, resolve
from phantom_pin.config.types import GIMBAL_JOINTS
from phantom_pin.description.build import Description, describe, shipped
from phantom_pin.dynamics._refusals import refusal
from phantom_pin.dynamics.build import rooted_at_frame
from phantom_pin.dynamics.fast import (
    BOOL,
    ONE,
    accelerations,
    attempt,
    coriolis,
    finite,
    frame_jacobian,
    is_one,
    isfinite,
    rows,
)
from phantom_pin.dynamics.fast import solve_spd as solve_spd  # (where it lived before)
from phantom_pin.dynamics.ik import SEEDS, solve_ik
from phantom_pin.dynamics.pinocchio_models import pinocchio_models
from phantom_pin.exceptions import InvalidInputError


class Phantom:
    """The PHANToM in the report's coordinates, computed by Pinocchio.

    One way to make each: ``Phantom(description)`` of a Description, the one result of reading a
    configuration (phantom_pin.describe(name or folder, overrides=..., prefix=...)), or
    ``Phantom()`` for the default model (premium_1_5, its committed URDF and SRDF); the named
    constructors for the rest, as Pinocchio's ``RobotWrapper(model, ...)`` beside
    ``RobotWrapper.BuildFromURDF``: ``Phantom.from_model(model)`` a named model
    (phantom_pin.models(), its committed files) and ``Phantom.from_folder(path)`` a
    configuration folder of one's own. Anything else given to the plain call (a name, a folder)
    is refused with InvalidInputError naming ``description`` and the constructor to use.

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
    tree model and the coupling matrix read from the URDF's mimic tags), ``full_coupling`` (the
    same with every joint of the URDF free: ``coupling`` itself without a gimbal), ``gimbal_joints``
    (the gimbal's joint names, () without one), ``stylus_model`` (the six-joint mimic model
    rooted at frame s, or None), ``threads`` (OpenMP threads of batched inverse dynamics).
    """

    def __init__(self, description: Description | None = None) -> None:
        if description is None:
            description = shipped()
        elif not isinstance(description, Description):
            raise refusal("Phantom", "a phantom_pin.Description or None", description, "description")
        self.description = description
        self.config: Config = description.config
        gimbal, prefix = self.config.gimbal, description.prefix
        self.gimbal_joints: tuple[str, ...] = () if gimbal is None else tuple(prefix + j for j in GIMBAL_JOINTS)
        built = pinocchio_models(description)
        #: every joint of the URDF free (the coupling itself without a gimbal): the ROS 2 node's frames
        self.full_coupling = built.full
        self.coupling = built.coupling
        self.model: pin.Model = self.coupling.reduced
        self.data = self.model.createData()
        self._tree_data = self.coupling.tree.createData()
        self._frame_s = self.model.getFrameId(prefix + "report_s")
        self._frame_tip = self.model.getFrameId(prefix + "tip")
        pin.framesForwardKinematics(self.model, self.data, pin.neutral(self.model))
        # report_s is fixed to the world: a copy of the model whose world is frame s gives
        # g_st and J^s directly (its joints' placements on the world premultiplied by g_s^-1)
        self._kinematics = rooted_at_frame(self.model, prefix + "report_s")
        self._kinematics_data = self._kinematics.createData()
        self.threads = os.cpu_count() or 1
        self._pool: pin.ModelPool | None = None
        #: the six joints' mimic model rooted at frame s, and its coupling's tree (the Coriolis matrix
        #: of the gimbal held, see coriolis_matrix), from the URDF with the gimbal free
        self.stylus_model: pin.Model | None = built.stylus
        self._stylus_coupling = built.full
        self._stylus_tree_data = built.full.tree.createData()
        self._frame_stylus = self._frame_stylus_tip = -1
        if built.stylus is not None and built.order is not None:
            #: the six-joint model's q (and, every joint revolute, v) of (theta, g): q[order] = (theta1..3, g1..3)
            self._order = built.order
            self._arm, self._arm_block = self._order[:3], np.ix_(self._order[:3], self._order[:3])
            self._stylus_data = built.stylus.createData()
            self._frame_stylus = built.stylus.getFrameId(f"{prefix}stylus")
            self._frame_stylus_tip = built.stylus.getFrameId(f"{prefix}stylus_tip")

    @classmethod
    def from_model(cls, model: str) -> Phantom:
        """The named model ``model`` (phantom_pin.models()), from its committed URDF and SRDF
        (equal to describe(model)'s, tests/description/test_build.py; the one Description
        of shipped(model), Phantom()'s for the default). InvalidInputError naming ``model`` for
        anything else."""
        if not (isinstance(model, str) and model in MODELS):
            renamed(model)
            raise InvalidInputError(f"expected one of {', '.join(MODELS)}, got {model!r}"
                                    + ("; for a configuration folder use Phantom.from_folder(path)"
                                       if isinstance(model, (str, Path)) else ""), argument="model")
        return cls(shipped(model))

    @classmethod
    def from_folder(cls, folder: str | Path) -> Phantom:
        """A configuration folder of one's own (its YAML files), through phantom_pin.describe;
        InvalidInputError naming ``folder`` for anything else (a model name too: that is
        Phantom.from_model)."""
        if isinstance(folder, str) and folder in MODELS:
            raise InvalidInputError(f"{folder!r} is a model name, not a folder; use Phantom.from_model({folder!r})",
                                    argument="folder")
        resolve(folder, "folder")  # InvalidInputError naming it unless a folder
        return cls(describe(folder))

    # -- helpers ---------------------------------------------------------------------
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
        out = rows(function, *(a.reshape(-1, a.shape[-1]) for a in arrays), before=before, after=after)
        return finite_result(out.reshape(arrays[0].shape[:-1] + out.shape[1:]), ", ".join(names))

    def _tree_batch(self, function: Callable[..., np.ndarray], names: tuple[str, ...],
                    theta: np.ndarray, *rates: np.ndarray, before: tuple = ()) -> np.ndarray:
        """``function(*before, q, *rates)`` of tree configurations and tangents over checked
        states, (3,) or (..., 3): the coupling maps the whole batch, Pinocchio runs per row,
        the results (N, ..., tree.nv, tree.nv) are projected at once; checked for
        finiteness (an overflow is reported by finite_result, not by NumPy's warnings)."""
        coupling = self.coupling
        with np.errstate(invalid="ignore", over="ignore"):
            tree = rows(function, coupling.configuration(theta.reshape(-1, 3)),
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
        if is_one(theta):  # the fast path, inline: attempt(self._pose, ...) costs 0.2 us of its 0.9
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
        if branch not in SEEDS:
            raise InvalidInputError(f"expected 'report' or 'other', got {branch!r}", argument="branch")
        kinematics = self._kinematics, self._kinematics_data, self._frame_tip, self.config.kinematics
        return self._each(lambda p: solve_ik(*kinematics, p, branch), ("position",), position)

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
        arm: Any = values  # finite vectors (3,) once is_one says so
        if self.stylus_model is not None and is_one(gimbal) and all(map(is_one, arm)):  # the fast path
            out = attempt(one, self._one_six(arm[0], gimbal), *(self._one_six(v, None) for v in arm[1:]))
            if out is not None and finite(out):  # rates can overflow
                return out
        arrays = self._six(names, gimbal, *values)
        with np.errstate(invalid="ignore", over="ignore"):  # reported by finite_result
            out = rows(one, *(a.reshape(-1, 6) for a in arrays))
        return finite_result(out.reshape(arrays[0].shape[:-1] + out.shape[1:]), ", ".join((*names, "gimbal")))

    # the arm's rows (and columns) of the six-joint model's dynamics at one state, for _held
    def _held_gravity(self, q: np.ndarray) -> np.ndarray:
        return pin.computeGeneralizedGravity(self.stylus_model, self._stylus_data, q)[self._arm]

    def _held_mass(self, q: np.ndarray) -> np.ndarray:
        return pin.crba(self.stylus_model, self._stylus_data, q)[self._arm_block]  # the full matrix, as mass_matrix's

    def _held_coriolis(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        return coriolis(self._stylus_coupling, self._stylus_tree_data, q, v)[self._arm_block]

    def _held_torques(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
        return pin.rnea(self.stylus_model, self._stylus_data, q, v, a)[self._arm]

    def _held_forward(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        model, data, arm = self.stylus_model, self._stylus_data, self._arm
        return accelerations(pin.crba(model, data, q)[self._arm_block],
                              tau[arm] - pin.nonLinearEffects(model, data, q, v)[arm])

    def _stylus_frame(self, frame: int, theta: object, gimbal: object, jacobian: bool = False) -> np.ndarray:
        model = self.stylus_model
        if is_one(theta) and is_one(gimbal) and model is not None and not jacobian:  # the fast path
            return self._stylus_placement(frame, self._one_six(theta, gimbal))
        (q,) = self._six(("theta",), gimbal, theta)
        model, data = self._stylus()

        def one(configuration: np.ndarray) -> np.ndarray:
            if jacobian:  # columns in (theta, g) order
                return pin.computeFrameJacobian(model, data, configuration, frame, pin.WORLD)[:, self._order]
            return self._stylus_placement(frame, configuration)

        out = np.array([one(c) for c in q.reshape(-1, 6)])
        return finite_result(out.reshape(q.shape[:-1] + out.shape[1:]), "theta, gimbal")

    def _stylus_placement(self, frame: int, q: np.ndarray) -> np.ndarray:
        """The stylus model's ``frame`` at the six-joint q: (4, 4)."""
        pin.forwardKinematics(self.stylus_model, self._stylus_data, q)
        return pin.updateFramePlacement(self.stylus_model, self._stylus_data, frame).homogeneous

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

    spatial_jacobian = frame_jacobian("spatial_jacobian", pin.WORLD, """Spatial Jacobian J^s (eq. 22): (..., 6, 3),
        twist (v, omega) in frame s.

        Pinocchio's WORLD frame Jacobian of ``tip`` in the model rooted at frame s.
        """)
    body_jacobian = frame_jacobian("body_jacobian", pin.LOCAL, """Body Jacobian J^b (eq. 24): (..., 6, 3),
        twist (v, omega) in the tool frame t.""")

    # -- dynamics --------------------------------------------------------------------
    def mass_matrix(self, theta: object, gimbal: object = None) -> np.ndarray:
        """Joint-space inertia M(theta) (eqs 81-85), with the rotors' armature: (..., 3, 3),
        kg m^2. ``gimbal`` (rad, a model with a gimbal only): held at those angles instead of at
        ``locked_at``, as in gravity."""
        if gimbal is not None:
            return self._held(self._held_mass, ("theta",), gimbal, theta)
        if is_one(theta) and (out := attempt(pin.crba, self.model, self.data, theta)) is not None:  # the fast path
            return out
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
        if is_one(theta) and is_one(dtheta):  # the fast path; rates can overflow C
            out = attempt(coriolis, self.coupling, self._tree_data, theta, dtheta)
            if out is not None and finite(out):
                return out
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
        if is_one(theta) and (out := attempt(pin.computeGeneralizedGravity, self.model, self.data, theta)) is not None:
            return out  # the fast path
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
        energy = rows(pin.computePotentialEnergy, self.coupling.configuration(q.reshape(-1, 3)),
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
            if (q.shape == dtheta.shape == ddtheta.shape == ONE  # type: ignore[attr-defined]
                    and BOOL is not q.dtype and BOOL is not dtheta.dtype  # type: ignore[attr-defined]
                    and BOOL is not ddtheta.dtype):  # type: ignore[attr-defined]
                tau = pin.rnea(self.model, self.data, theta, dtheta, ddtheta)  # (a fresh array)
                # NaN/inf in any input, or an overflow, reaches tau (tests/dynamics/test_fast.py);
                # only then are the inputs inspected, to name the bad one.
                t0, t1, t2 = tau.tolist()
                if isfinite(t0 + t1 + t2):
                    return tau
        except (AttributeError, TypeError):  # no shape (lists), or not for eigenpy
            pass
        names = ("theta", "dtheta", "ddtheta")
        q, v, a = self._states(names, theta, dtheta, ddtheta)
        if q.ndim == 1:
            return finite_result(pin.rnea(self.model, self.data, q, v, a), ", ".join(names))
        return finite_result(self._batched(q, v, a), ", ".join(names))

    def _forward(self, theta: np.ndarray, dtheta: np.ndarray, tau: np.ndarray) -> np.ndarray:
        return accelerations(pin.crba(self.model, self.data, theta),
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
        if is_one(theta):
            try:
                t0, t1, t2 = torques.tolist()
                if rates.shape == ONE and t0.__class__ is not bool and rates.dtype is not BOOL:
                    model, data = self.model, self.data
                    bias = pin.nonLinearEffects(model, data, theta, dtheta).tolist()
                    acc = solve_spd(pin.crba(model, data, theta).tolist(),
                                    (t0 - bias[0], t1 - bias[1], t2 - bias[2]))
                    if acc is not None and isfinite(sum(acc)):  # rates can overflow
                        return np.array(acc)
            except (AttributeError, TypeError, ValueError):  # no shape, not for eigenpy, complex tau
                pass
        names = ("theta", "dtheta", "tau")
        q, v, torque = self._states(names, theta, dtheta, tau)
        if q.ndim == 1:
            return finite_result(self._forward(q, v, torque), ", ".join(names))
        with np.errstate(invalid="ignore", over="ignore"):  # reported by finite_result
            rhs = torque - self._batched(q, v, np.zeros_like(q))
        mass = rows(pin.crba, q.reshape(-1, 3), before=(self.model, self.data)).reshape(q.shape + (3,))
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
        if is_one(theta) and is_one(dtheta) and is_one(ddtheta):  # the fast path; rates can overflow
            tree = attempt(self._tree_derivatives, coupling.configuration(theta), coupling.tangent(dtheta),
                           coupling.tangent(ddtheta))
            both = None if tree is None else coupling.project(tree)
            if both is not None and finite(both):
                return both[0], both[1]
        names = ("theta", "dtheta", "ddtheta")
        both = self._tree_batch(self._tree_derivatives, names, *self._states(names, theta, dtheta, ddtheta))
        return both[..., 0, :, :].copy(), both[..., 1, :, :].copy()
