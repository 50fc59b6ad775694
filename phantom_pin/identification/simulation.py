"""A simulated PHANToM for testing identification: the report's closed-form dynamics with
any parameters, friction, torque noise and encoder quantization, tracking a trajectory.

Integration: classical RK4 (phantom_pin.integration) at the log's rate with the commanded torque held over each step
(zero-order hold). Controller: the inverse dynamics of the parameters model along the
reference plus PD feedback (on the quantized position and the true velocity). Logged: time,
the quantized positions and the *commanded* torques, as a real device's log.
"""

from __future__ import annotations

from typing import Callable

import numpy as np

from phantom_pin.config import Friction
from phantom_pin.identification.io import Log
from phantom_pin.integration import rk4_step
from phantom_pin.report import closed_form
from phantom_pin.report.parameters import ReportParameters


def simulate(reference: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray, np.ndarray]],
             duration: float, truth: ReportParameters, model: ReportParameters, friction: Friction,
             rate: float = 1000.0, torque_noise: float = 0.0,
             resolution: np.ndarray | float = 0.0, kp: float = 5.0, kd: float = 0.05,
             seed: int = 0) -> Log:
    """Track ``reference(t) -> (theta, dtheta, ddtheta)`` (rad, rad/s, rad/s^2 at (N,) times)
    for ``duration`` s on the device ``truth``, fed forward with the inverse dynamics of
    ``model`` (the parameters the controller believes), with the friction law ``friction``
    (phantom_pin.config.Friction, the same on each joint). ``torque_noise``: standard
    deviation (N m) of white noise added to the applied torque; ``resolution``: encoder step
    at the joint (rad); kp (N m/rad), kd (N m s/rad): feedback gains."""
    rng = np.random.default_rng(seed)
    n = int(round(duration * rate)) + 1
    t = np.arange(n) / rate
    dt = 1.0 / rate
    ref_q, ref_v, ref_a = reference(t)
    feedforward = closed_form.inverse_dynamics(ref_q, ref_v, ref_a, model)
    resolution = np.broadcast_to(np.asarray(resolution, float), 3)

    def quantize(q):
        return np.where(resolution > 0, np.round(q / np.where(resolution > 0, resolution, 1)) * resolution, q)

    def acceleration(q, v, torque):
        bias = closed_form.coriolis_matrix(q, v, truth) @ v + closed_form.gravity(q, truth)
        return np.linalg.solve(closed_form.mass_matrix(q, truth), torque - friction.torque(v) - bias)

    q, v = ref_q[0].copy(), ref_v[0].copy()
    measured, commanded = np.empty((n, 3)), np.empty((n, 3))
    for i in range(n):
        measured[i] = quantize(q)
        commanded[i] = feedforward[i] + kp * (ref_q[i] - measured[i]) + kd * (ref_v[i] - v)
        applied = commanded[i] + torque_noise * rng.standard_normal(3)
        q, v = rk4_step(lambda q_, v_: acceleration(q_, v_, applied), q, v, dt)
    return Log(t, measured, commanded)
