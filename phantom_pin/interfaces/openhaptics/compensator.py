"""Gravity (and friction) compensation for an OpenHaptics servo callback in Python.

pyOpenHaptics (PyPI) runs a Python function as OpenHaptics' servo callback, between
hdBeginFrame and hdEndFrame; one call of a ``Compensator`` a tick turns the tick's angles into
what to send::

    compensate = Compensator("touch")                  # mode "force": HD_CURRENT_FORCE, N

    @hd_callback
    def servo():
        hd.set_force(compensate(hd.get_joints(), hd.get_gimbals()))

``joints``: HD_CURRENT_JOINT_ANGLES (rad, three numbers: pyOpenHaptics' get_joints()),
``gimbals``: HD_CURRENT_GIMBAL_ANGLES (rad; get_gimbals(); None, or left out, on a model
without a stylus gimbal, where they are ignored). In mode "force" the result is
HD_CURRENT_FORCE (N, OpenHaptics' axes) with J_p^T F = N(theta, gimbal); in mode
"joint_torque" HD_CURRENT_JOINT_TORQUE (mN m on OpenHaptics' angles): the same as the
generated C header's NAME_openhaptics_force and NAME_openhaptics_joint_torque. With
``friction=True``, ``rates`` (the rates of HD_CURRENT_JOINT_ANGLES, rad/s, the caller's
estimate) is required and the model's friction law in motion is added (Device.friction).
The cost is measured by benchmarks/bench_openhaptics.py.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from phantom_pin.exceptions import InvalidInputError

#: What a Compensator computes: HD_CURRENT_FORCE (N) or HD_CURRENT_JOINT_TORQUE (mN m).
MODES = ("force", "joint_torque")


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


class Compensator:
    """``Compensator(model="premium_1_5", mode="force", friction=False)``: the call a tick of
    the module's doc. ``model``: a model's name or a configuration folder (phantom_pin.models());
    ``mode`` one of MODES. InvalidInputError naming the argument for a bad one, and at each
    call for angles that are not three finite numbers, gimbal angles on a model without a
    stylus gimbal, or missing rates with friction; a singular posture (no force gives the
    gravity torques, mode "force") raises InvalidInputError naming ``joints``."""

    def __init__(self, model: object = "premium_1_5", mode: str = "force", friction: bool = False) -> None:
        from phantom_pin.description.build import description_of
        from phantom_pin.device.device import Device
        from phantom_pin.drivers import openhaptics_from_theta
        from phantom_pin.dynamics.model import Phantom

        if mode not in MODES:
            raise InvalidInputError(f"expected one of {', '.join(MODES)}, got {mode!r}", argument="mode")
        if not isinstance(friction, bool):
            raise InvalidInputError(f"expected True or False, got {friction!r}", argument="friction")
        self.phantom = Phantom(description_of(model, "model"))
        self.device = Device(self.phantom)
        self.mode, self.friction = mode, friction
        self.has_gimbal = self.phantom.config.gimbal is not None
        #: da/dtheta, diagonal (OpenHaptics' angles are linear in theta): theta = S a, tau_a = S tau
        self._sign = np.diag(openhaptics_from_theta(np.eye(3)))
        self._law = self.phantom.config.actuation.friction

    def __call__(self, joints: Sequence[float], gimbals: Sequence[float] | None = None,
                 rates: Sequence[float] | None = None) -> list[float]:
        """HD_CURRENT_FORCE (N) or HD_CURRENT_JOINT_TORQUE (mN m) as a list of three floats."""
        theta = _three(joints, "joints") * self._sign
        locked = self.phantom.config.gimbal
        if locked is not None:
            gimbal = np.array(locked.locked_at) if gimbals is None else _three(gimbals, "gimbals")
            tau = self.phantom.gravity(theta, gimbal=gimbal)
        else:
            if gimbals is not None:
                raise InvalidInputError(f"the model {self.phantom.config.name!r} has no stylus gimbal: pass no "
                                        "gimbal angles", argument="gimbals")
            tau = self.phantom.gravity(theta)
        if self.friction:
            if rates is None:
                raise InvalidInputError("friction compensation needs the joint angles' rates (rad/s)",
                                        argument="rates")
            tau = tau + np.asarray(self._law.torque(_three(rates, "rates") * self._sign))
        elif rates is not None:
            raise InvalidInputError("rates are for friction=True", argument="rates")
        if self.mode == "joint_torque":
            return (tau * self._sign * 1000.0).tolist()
        jacobian = self.device.tip_jacobian(theta)
        if abs(np.linalg.det(jacobian)) < 1e-12:
            raise InvalidInputError(f"singular posture (theta {theta.tolist()!r} rad): no tip force gives the "
                                    "gravity torques; use mode 'joint_torque'", argument="joints")
        return np.linalg.solve(jacobian.T, tau).tolist()
