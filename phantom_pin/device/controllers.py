"""Controllers for simulate() and simulate_mujoco(): callables (t s, theta rad, dtheta rad/s)
-> joint torques (N m), in the report's coordinates."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from phantom_pin._validation import fixed_rate

#: The PD gains of the tracking controller (N m/rad, N m s/rad).
KP, KD = 5.0, 0.05


def tracking(t: np.ndarray, theta: np.ndarray, dtheta: np.ndarray, tau: np.ndarray,
             kp: float = KP, kd: float = KD) -> Callable[[float, np.ndarray, np.ndarray], np.ndarray]:
    """The controller (simulate's) that follows a trajectory sampled at the fixed rate of ``t``
    (s; theta rad, dtheta rad/s, tau the feed-forward torque N m, each (N, 3)): at time s it
    returns tau[k] + kp (theta[k] - theta_measured) + kd (dtheta[k] - dtheta_measured), k the
    sample at t[0] + s (the last one after the end): simulate's time starts at 0."""
    rate = fixed_rate(t)

    def controller(time: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        k = min(int(round(time * rate)), len(t) - 1)
        return tau[k] + kp * (theta[k] - q) + kd * (dtheta[k] - v)
    return controller
