"""Phantom: the report's kinematics and dynamics, computed by Pinocchio on the URDF model."""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Callable

import numpy as np
import pinocchio as pin

from phantom_pin.coupling import Coupling
from phantom_pin.description import Description, describe, shipped
from phantom_pin.exceptions import InvalidInputError, UnreachableTargetError
from phantom_pin.loader import load_rotor_parameters
from phantom_pin.parameters import Parameters
from phantom_pin.paths import CONFIG_DIR
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


_FLOAT = np.dtype(float)  # a singleton: ``array.dtype is _FLOAT`` for float64 arrays


class Phantom:
    """The PHANToM 1.5 in the report's coordinates, computed by Pinocchio.

    ``Phantom()`` loads the shipped URDF and SRDF. ``Phantom(config_dir=...)``, or
    any of the xacro file arguments of ``parameters.PARAMETER_FILES`` (for example
    ``Phantom(physical_parameters_file="mine.yaml")``), generates them through xacro
    from modified parameter files; ``Phantom(description)`` takes a Description
    (phantom_pin.describe), the one result of reading a configuration.

    Joint vectors are the report's theta1..theta3 (rad), which are the URDF's
    joint1..joint3; rates in rad/s, accelerations in rad/s^2, torques in N m. Poses
    are in the report's kinematic frame s (URDF frame ``report_s``: x left, y up,
    z forward); the tool frame t is ``tip``. Every method takes one state, shape (3,),
    or a batch, shape (N, 3), and returns fresh arrays.

    Attributes: ``description`` (the Description it was built from), ``model`` (the mimic model, nq = nv = 3, armature = the SRDF's rotor
    inertias times ratio^2), ``data``, ``coupling`` (the mimic-free tree model and the
    coupling matrix read from the URDF's mimic tags), ``parameters`` (the report's
    numbers), ``threads`` (OpenMP threads of batched inverse dynamics).
    """

    def __init__(self, config_dir: Description | Path | str | None = None, **files: Path | str) -> None:
        if isinstance(config_dir, Description):
            description = config_dir
        elif config_dir is None and not files:
            description = shipped()
        else:
            description = describe(CONFIG_DIR if config_dir is None else config_dir, **files)
        self.description = description
        self.parameters: Parameters = description.parameters
        self.coupling = Coupling(description.urdf)
        self.model: pin.Model = self.coupling.reduced
        load_rotor_parameters(self.model, description.srdf)
        self.data = self.model.createData()
        self._tree_data = self.coupling.tree.createData()
        self._frame_s = self.model.getFrameId("report_s")
        self._frame_tip = self.model.getFrameId("tip")
        pin.framesForwardKinematics(self.model, self.data, pin.neutral(self.model))
        #: report_s is fixed to base_link: Ad(g_s^-1) maps world twists to frame s.
        self._world_to_s = self.data.oMf[self._frame_s].inverse().action
        self.threads = os.cpu_count() or 1
        self._pool: pin.ModelPool | None = None

    # -- helpers ---------------------------------------------------------------------
    @staticmethod
    def _states(names: tuple[str, ...], *values: object) -> list[np.ndarray]:
        arrays = [as_states(v, n)[0] for n, v in zip(names, values)]
        same_batch(names, *arrays)
        return arrays

    @classmethod
    def _each(cls, function: Callable[..., np.ndarray], names: tuple[str, ...],
              *values: object) -> np.ndarray:
        """Check ``values`` (named ``names``) and apply a one-state function over their
        leading axes; raise InvalidInputError naming them if the result is not finite."""
        arrays = cls._states(names, *values)
        if arrays[0].ndim == 1:
            out = function(*arrays)
        else:
            out = np.stack([function(*row) for row in zip(*(a.reshape(-1, 3) for a in arrays))])
            out = out.reshape(arrays[0].shape[:-1] + out.shape[1:])
        return finite_result(out, ", ".join(names))

    def within_limits(self, theta: object) -> bool | np.ndarray:
        """True where ``theta`` (rad), shape (3,) or (..., 3), lies inside the URDF's box
        joint limits (``model.lowerPositionLimit`` <= theta <= ``upperPositionLimit``,
        bounds included): a bool for one state, a bool array of shape (...) for a batch.

        Every method computes outside the limits too (the model is valid there); ask
        this to flag such states. The physical device's stops, coupled ones included,
        are narrower or wider per joint and are not these.
        """
        return within_box(theta, self.model.lowerPositionLimit, self.model.upperPositionLimit)

    def _placement(self, theta: np.ndarray) -> pin.SE3:
        """Pose of tip in report_s after forward kinematics at theta."""
        pin.framesForwardKinematics(self.model, self.data, theta)
        return self.data.oMf[self._frame_s].actInv(self.data.oMf[self._frame_tip])

    def _symmetric_mass(self, theta: np.ndarray) -> np.ndarray:
        upper = pin.crba(self.model, self.data, theta)
        return np.triu(upper) + np.triu(upper, 1).T

    # -- kinematics ------------------------------------------------------------------
    def forward_kinematics(self, theta: object) -> np.ndarray:
        """Pose g_st of the tool frame t in frame s (eq. 10): shape (..., 4, 4), metres."""
        return self._each(lambda x: self._placement(x).homogeneous, ("theta",), theta)

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
        p = self.parameters
        shoulder = np.array([0.0, p.l2, -p.l1])  # the shoulder in frame s (eqs 4-5)
        distance = float(np.linalg.norm(target - shoulder))
        if not abs(p.l1 - p.l2) * (1 - 1e-12) <= distance <= (p.l1 + p.l2) * (1 + 1e-12):
            raise UnreachableTargetError(
                f"position: {np.array2string(target, precision=4)} m is {distance:.4f} m from "
                f"the shoulder, outside the reachable shell [{abs(p.l1 - p.l2):.4f}, "
                f"{p.l1 + p.l2:.4f}] m")
        sign = 1.0 if branch == "report" else -1.0
        for seed in _IK_SEEDS[branch]:
            theta = self._newton(target, np.array([math.atan2(target[0], target[2] + p.l1), *seed]))
            # the report's branch has the elbow open forwards, cos(theta3 - theta2) =
            # sin(alpha) >= 0; on the shell's boundaries (alpha = 0 or pi) both branches
            # meet, where Newton's angles are good to about sqrt(tolerance / l) ~ 1e-6 rad
            if theta is not None and sign * math.cos(theta[2] - theta[1]) > -_IK_BRANCH_SLACK:
                return wrap_angle(theta)
        raise UnreachableTargetError(
            f"position: no {branch}-branch solution found for {target} m")

    def _newton(self, target: np.ndarray, theta: np.ndarray) -> np.ndarray | None:
        """Damped Newton on the tip position from ``theta``; None if it does not converge."""
        for _ in range(_IK_ITERATIONS):
            tip = self._placement(theta).translation
            error = target - tip
            if np.linalg.norm(error) < _IK_TOLERANCE:
                return theta
            jacobian = self._spatial_jacobian(theta)
            # velocity of the tip point in s: v + omega x p (J^s is taken at s's origin)
            linear = jacobian[:3] + np.cross(jacobian[3:].T, tip).T
            step = np.linalg.solve(linear.T @ linear + _IK_DAMPING * np.eye(3), linear.T @ error)
            theta = theta + step * min(1.0, _IK_MAX_STEP / np.abs(step).max())
        return None

    def _spatial_jacobian(self, theta: np.ndarray) -> np.ndarray:
        return self._world_to_s @ pin.computeFrameJacobian(self.model, self.data, theta,
                                                            self._frame_tip, pin.WORLD)

    def spatial_jacobian(self, theta: object) -> np.ndarray:
        """Spatial Jacobian J^s (eq. 22): (..., 6, 3), twist (v, omega) in frame s.

        Pinocchio's WORLD frame Jacobian of ``tip``, moved to frame s by Ad(g_s^-1).
        """
        return self._each(self._spatial_jacobian, ("theta",), theta)

    def body_jacobian(self, theta: object) -> np.ndarray:
        """Body Jacobian J^b (eq. 24): (..., 6, 3), twist (v, omega) in the tool frame t."""
        def one(x: np.ndarray) -> np.ndarray:
            return pin.computeFrameJacobian(self.model, self.data, x, self._frame_tip, pin.LOCAL)
        return self._each(one, ("theta",), theta)

    # -- dynamics --------------------------------------------------------------------
    def mass_matrix(self, theta: object) -> np.ndarray:
        """Joint-space inertia M(theta) (eqs 81-85), with the rotors' armature: (..., 3, 3)."""
        return self._each(self._symmetric_mass, ("theta",), theta)

    def coriolis_matrix(self, theta: object, dtheta: object) -> np.ndarray:
        """Coriolis matrix C(theta, dtheta) (eqs 86-92): (..., 3, 3), N m s/rad.

        Pinocchio's computeCoriolisMatrix is silently wrong on mimic models, so it runs
        on the tree model and is projected: C = G^T C_tree G.
        """
        tree, coupling = self.coupling.tree, self.coupling

        def one(x: np.ndarray, dx: np.ndarray) -> np.ndarray:
            c = pin.computeCoriolisMatrix(tree, self._tree_data, coupling.configuration(x),
                                          coupling.tangent(dx))
            return coupling.project(c)
        return self._each(one, ("theta", "dtheta"), theta, dtheta)

    def gravity(self, theta: object) -> np.ndarray:
        """Gravity torque N(theta) (eqs 93-94): (..., 3), N m."""
        return self._each(lambda x: pin.computeGeneralizedGravity(self.model, self.data, x).copy(),
                          ("theta",), theta)

    def potential_energy(self, theta: object) -> np.ndarray:
        """Potential energy V(theta) (J), zero with every centre of mass at shoulder height."""
        tree, coupling = self.coupling.tree, self.coupling

        def one(x: np.ndarray) -> np.ndarray:
            return np.array(pin.computePotentialEnergy(tree, self._tree_data, coupling.configuration(x)))
        return self._each(one, ("theta",), theta)

    def inverse_dynamics(self, theta: object, dtheta: object, ddtheta: object) -> np.ndarray:
        """Joint torques tau = M ddtheta + C dtheta + N (eq. 80): (..., 3), N m.

        One state: pinocchio.rnea on the mimic model. A batch (N, 3):
        pinocchio.rneaInParallel over ``threads`` OpenMP threads.
        """
        if (type(theta) is type(dtheta) is type(ddtheta) is np.ndarray  # the fast path: one
                and theta.dtype is dtheta.dtype is ddtheta.dtype is _FLOAT     # real state (3,)
                and theta.shape == dtheta.shape == ddtheta.shape == (3,)):
            tau = pin.rnea(self.model, self.data, theta, dtheta, ddtheta)
            # NaN/inf in any input, or an overflow, reaches tau; only then are the
            # inputs inspected, to name the bad one.
            if math.isfinite(tau[0]) and math.isfinite(tau[1]) and math.isfinite(tau[2]):
                return tau.copy()
        names = ("theta", "dtheta", "ddtheta")
        q, v, a = self._states(names, theta, dtheta, ddtheta)
        if q.ndim == 1:
            return finite_result(pin.rnea(self.model, self.data, q, v, a).copy(), ", ".join(names))
        if self._pool is None or self._pool.size() < self.threads:
            self._pool = pin.ModelPool(self.model, self.threads)
        shape = q.shape
        tau = np.empty((3, math.prod(shape[:-1])), order="F")
        pin.rneaInParallel(self.threads, self._pool, q.reshape(-1, 3).T, v.reshape(-1, 3).T,
                           a.reshape(-1, 3).T, tau)
        return finite_result(tau.T.reshape(shape), ", ".join(names))

    def forward_dynamics(self, theta: object, dtheta: object, tau: object) -> np.ndarray:
        """Joint accelerations (rad/s^2) under torques ``tau`` (N m): M^-1 (tau - C dtheta - N).

        pinocchio.aba refuses mimic models, so M (crba) and the bias torques
        (nonLinearEffects) come from Pinocchio and the 3x3 system is solved by Cholesky.
        """
        def one(x: np.ndarray, dx: np.ndarray, torque: np.ndarray) -> np.ndarray:
            bias = pin.nonLinearEffects(self.model, self.data, x, dx)
            factor = np.linalg.cholesky(self._symmetric_mass(x))
            return np.linalg.solve(factor.T, np.linalg.solve(factor, torque - bias))
        return self._each(one, ("theta", "dtheta", "tau"), theta, dtheta, tau)

    def inverse_dynamics_derivatives(self, theta: object, dtheta: object,
                                     ddtheta: object) -> tuple[np.ndarray, np.ndarray]:
        """(d tau / d theta, d tau / d dtheta), each (..., 3, 3), in N m/rad and N m s/rad.

        Pinocchio's RNEA derivatives refuse mimic models; they run on the tree model
        and are projected: d tau/d theta = G^T (d tau_tree/d q) G, and likewise for dtheta.
        """
        tree, coupling = self.coupling.tree, self.coupling

        def one(x: np.ndarray, dx: np.ndarray, ddx: np.ndarray) -> np.ndarray:
            d_q, d_v, _ = pin.computeRNEADerivatives(
                tree, self._tree_data, coupling.configuration(x), coupling.tangent(dx),
                coupling.tangent(ddx))
            return np.stack([coupling.project(d_q), coupling.project(d_v)])
        both = self._each(one, ("theta", "dtheta", "ddtheta"), theta, dtheta, ddtheta)
        return both[..., 0, :, :].copy(), both[..., 1, :, :].copy()
