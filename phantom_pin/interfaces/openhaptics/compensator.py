"""Compensation for an OpenHaptics servo callback in Python: gravity, and beyond it friction and
a share of the inertia.

pyOpenHaptics (PyPI) runs a Python function as OpenHaptics' servo callback, between
hdBeginFrame and hdEndFrame; one call of a ``Compensator`` a tick turns the tick's angles into
what to send::

    compensate = Compensator("touch")                  # mode "force": HD_CURRENT_FORCE, N

    @hd_callback
    def servo():
        hd.set_force(compensate(hd.get_joints(), hd.get_gimbals()))

``joints``: HD_CURRENT_JOINT_ANGLES (rad, three numbers: pyOpenHaptics' get_joints()),
``gimbals``: HD_CURRENT_GIMBAL_ANGLES (rad; get_gimbals(); None, or left out, on a model
without a stylus gimbal). In mode "force" the result is HD_CURRENT_FORCE (N, OpenHaptics' axes)
with J_p^T F = tau; in mode "joint_torque" HD_CURRENT_JOINT_TORQUE (mN m on OpenHaptics'
angles), tau the sum of the terms of ``compensate`` (TERMS):

- "gravity": N(theta, gimbal), as the generated header's NAME_openhaptics_force;
- "friction": the model's friction law in motion (Device.friction; or ``friction``, e.g. an
  identified overlay's) at the joint rate, 0 for a joint slower than ``dead_band`` (rad/s: a
  compensation that pushed a resting joint would start it moving);
- "inertia": ``kappa`` (M(theta) ddtheta + C(theta, dtheta) dtheta), 0 <= kappa < 1, which
  leaves (1 - kappa) of the arm's inertia to the hand; applied only while some joint moves
  faster than ``dead_band`` (the signal's quality: at rest the estimates are the encoder's
  steps differentiated, noise the term would amplify).

The rates and accelerations are estimated from the successive calls at ``rate`` Hz
(device.estimator.Estimator, ``cutoff`` Hz), or taken from ``rates`` where the caller gives them
(friction only). The total is bounded as OpenHaptics and the motors bound it: a force to the device's
HD_NOMINAL_MAX_FORCE (its norm, direction kept; actuation.yaml's openhaptics), and the joint
torques to the motors' peak for short forces and their continuous rating on average
(device.thermal.TorqueBudget, one call a servo period: a force scaled, its direction kept; joint
torques clipped per joint); the result is never non-finite. The cost is measured by
benchmarks/bench_openhaptics.py.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from phantom_pin.config.types import Friction
from phantom_pin.device.estimator import REST
from phantom_pin.exceptions import InvalidInputError

#: What a Compensator computes: HD_CURRENT_FORCE (N) or HD_CURRENT_JOINT_TORQUE (mN m).
MODES = ("force", "joint_torque")
#: What it may compensate.
TERMS = ("gravity", "friction", "inertia")
#: The dead band's default (rad/s): below it a joint counts as at rest (device.estimator.REST).
DEAD_BAND = REST


def _three(values: object, argument: str) -> np.ndarray:
    try:
        out = np.array([float(values[0]), float(values[1]), float(values[2])])   # type: ignore[index]
        if len(values) != 3:                                                       # type: ignore[arg-type]
            raise ValueError
    except (TypeError, ValueError, IndexError, KeyError):
        raise InvalidInputError(f"expected three numbers (rad), got {values!r}", argument=argument) from None
    if not (math.isfinite(out[0]) and math.isfinite(out[1]) and math.isfinite(out[2])):
        raise InvalidInputError(f"expected finite numbers, got {values!r}", argument=argument)
    return out


def _terms(compensate: object, kappa: object) -> tuple[str, ...]:
    if isinstance(compensate, str) or not isinstance(compensate, Sequence) or \
            not set(compensate) <= set(TERMS) or not compensate:
        raise InvalidInputError(f"expected some of {', '.join(TERMS)}, got {compensate!r}", argument="compensate")
    if isinstance(kappa, bool) or not isinstance(kappa, (int, float)) or not 0 <= kappa < 1:
        raise InvalidInputError(f"expected a share 0 <= kappa < 1, got {kappa!r}", argument="kappa")
    if "inertia" in compensate and kappa == 0:
        raise InvalidInputError("inertia compensation needs a share kappa > 0", argument="kappa")
    return tuple(compensate)


class Compensator:
    """``Compensator(model, mode="force", compensate=("gravity",), *, kappa=0.0, rate=1000.0,
    cutoff=CUTOFF, dead_band=DEAD_BAND, friction=None)``: the call a tick of the module's doc.
    ``model``: a model's name or a configuration folder (phantom_pin.models()). InvalidInputError
    naming the argument for a bad one, and at each call for angles that are not three finite
    numbers or gimbal angles on a model without a stylus gimbal; a singular posture in mode
    "force" (no tip force gives the torques) raises InvalidInputError naming ``joints``."""

    def __init__(self, model: object, mode: str = "force", compensate: Sequence[str] = ("gravity",), *,
                 kappa: float = 0.0, rate: float = 1000.0, cutoff: float | None = None,
                 dead_band: float = DEAD_BAND, friction: Friction | None = None) -> None:
        from phantom_pin.description.build import description_of
        from phantom_pin.device.device import Device
        from phantom_pin.device.estimator import CUTOFF, Estimator
        from phantom_pin.device.thermal import TorqueBudget
        from phantom_pin.dynamics.phantom import Phantom
        from phantom_pin.interfaces.conventions import openhaptics_from_theta

        if mode not in MODES:
            raise InvalidInputError(f"expected one of {', '.join(MODES)}, got {mode!r}", argument="mode")
        self.terms = _terms(compensate, kappa)
        if isinstance(dead_band, bool) or not isinstance(dead_band, (int, float)) or not 0 <= dead_band < math.inf:
            raise InvalidInputError(f"expected a rate >= 0 rad/s, got {dead_band!r}", argument="dead_band")
        if friction is not None and not isinstance(friction, Friction):
            raise InvalidInputError(f"expected a config.Friction, got {friction!r}", argument="friction")
        self.phantom = Phantom(description_of(model, "model"))
        self.device = Device(self.phantom)
        self.mode, self.kappa, self.dead_band = mode, float(kappa), float(dead_band)
        self.estimator = Estimator(rate, CUTOFF if cutoff is None else cutoff)
        self.has_gimbal = self.phantom.config.gimbal is not None
        #: da/dtheta, diagonal (OpenHaptics' angles are linear in theta): theta = S a, tau_a = S tau
        self._sign = np.diag(openhaptics_from_theta(np.eye(3)))
        self.law = friction if friction is not None else self.phantom.config.actuation.friction
        if "friction" in self.terms and not any(self.law.viscous) and not any(self.law.coulomb):
            raise InvalidInputError(f"the model {self.phantom.config.name!r} has no friction data (every viscous and "
                                    "Coulomb coefficient 0): give friction= (an identified overlay's)",
                                    argument="compensate")
        openhaptics = self.phantom.config.actuation.openhaptics
        self.max_force = math.inf if openhaptics is None else openhaptics.max_force       # N, the norm
        self.budget = TorqueBudget(self.device, 1.0 / rate)                               # the motors' limits in time

    def _gimbal(self, gimbals: Sequence[float] | None) -> np.ndarray | None:
        locked = self.phantom.config.gimbal
        if locked is None:
            if gimbals is not None:
                raise InvalidInputError(f"the model {self.phantom.config.name!r} has no stylus gimbal: pass no "
                                        "gimbal angles", argument="gimbals")
            return None
        return np.array(locked.locked_at) if gimbals is None else _three(gimbals, "gimbals")

    def torque(self, joints: Sequence[float], gimbals: Sequence[float] | None = None,
               rates: Sequence[float] | None = None) -> np.ndarray:
        """The joint torques tau (N m on theta) of the terms, updating the estimates."""
        theta = _three(joints, "joints") * self._sign
        gimbal = self._gimbal(gimbals)
        rate, acceleration = self.estimator.update(theta) if self.terms != ("gravity",) else (np.zeros(3),) * 2
        if rates is not None:
            rate = _three(rates, "rates") * self._sign
        gravity = self.phantom.gravity(theta) if gimbal is None else self.phantom.gravity(theta, gimbal=gimbal)
        tau = gravity.copy() if "gravity" in self.terms else np.zeros(3)
        moving = np.abs(rate) > self.dead_band
        if "friction" in self.terms:
            tau += np.asarray(self.law.torque(np.where(moving, rate, 0.0)))
        if "inertia" in self.terms and moving.any():
            tau += self.kappa * (self.phantom.inverse_dynamics(theta, rate, acceleration, gimbal=gimbal) - gravity)
        return tau

    def __call__(self, joints: Sequence[float], gimbals: Sequence[float] | None = None,
                 rates: Sequence[float] | None = None) -> list[float]:
        """HD_CURRENT_FORCE (N) or HD_CURRENT_JOINT_TORQUE (mN m), bounded, as a list of three floats."""
        tau = self.torque(joints, gimbals, rates)
        if self.mode == "joint_torque":
            return (self.budget.clip(tau) * self._sign * 1000.0).tolist()
        theta = _three(joints, "joints") * self._sign
        jacobian = self.device.tip_jacobian(theta)
        if abs(np.linalg.det(jacobian)) < 1e-12:
            raise InvalidInputError(f"singular posture (theta {theta.tolist()!r} rad): no tip force gives the "
                                    "torques; use mode 'joint_torque'", argument="joints")
        force = np.linalg.solve(jacobian.T, tau)
        norm = float(np.linalg.norm(force))
        force = force * (self.max_force / norm) if norm > self.max_force else force
        return (force * self.budget.scale(jacobian.T @ force)).tolist()
