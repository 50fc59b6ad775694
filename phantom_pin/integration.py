"""The one integrator: a classical fourth-order Runge-Kutta step of a second-order system."""

from __future__ import annotations

from typing import Callable

import numpy as np


def rk4_step(acceleration: Callable[[np.ndarray, np.ndarray], np.ndarray], q: np.ndarray, v: np.ndarray,
             h: float) -> tuple[np.ndarray, np.ndarray]:
    """(q, v) after one classical RK4 step of h (s) of q'' = acceleration(q, v) (positions
    in rad, rates in rad/s, accelerations in rad/s^2); the inputs are not changed."""
    a1 = acceleration(q, v)
    q2, v2 = q + 0.5 * h * v, v + 0.5 * h * a1
    a2 = acceleration(q2, v2)
    q3, v3 = q + 0.5 * h * v2, v + 0.5 * h * a2
    a3 = acceleration(q3, v3)
    q4, v4 = q + h * v3, v + h * a3
    a4 = acceleration(q4, v4)
    return q + h / 6 * (v + 2 * v2 + 2 * v3 + v4), v + h / 6 * (a1 + 2 * a2 + 2 * a3 + a4)
