"""The one integrator: a classical fourth-order Runge-Kutta step of a second-order system."""

from __future__ import annotations

from typing import Callable

import numpy as np


def rk4_step(acceleration: Callable[[np.ndarray, np.ndarray], np.ndarray], q: np.ndarray, v: np.ndarray,
             h: float) -> tuple[np.ndarray, np.ndarray]:
    """(q, v) after one classical RK4 step of h (s) of q'' = acceleration(q, v) (positions
    in rad, rates in rad/s, accelerations in rad/s^2); the inputs are not changed. The stages'
    arithmetic runs on Python floats (for the 3-vectors of the arm, NumPy's per-operation cost
    exceeded the acceleration's; benchmarks/bench_plants.py); ``acceleration`` gets arrays and
    returns an array or a sequence of floats."""
    half, sixth = 0.5 * h, h / 6.0
    qs, vs = q.tolist(), v.tolist()
    a1 = _floats(acceleration(q, v))
    q2 = [x + half * y for x, y in zip(qs, vs)]
    v2 = [x + half * y for x, y in zip(vs, a1)]
    a2 = _floats(acceleration(np.array(q2), np.array(v2)))
    q3 = [x + half * y for x, y in zip(qs, v2)]
    v3 = [x + half * y for x, y in zip(vs, a2)]
    a3 = _floats(acceleration(np.array(q3), np.array(v3)))
    q4 = [x + h * y for x, y in zip(qs, v3)]
    v4 = [x + h * y for x, y in zip(vs, a3)]
    a4 = _floats(acceleration(np.array(q4), np.array(v4)))
    return (np.array([x + sixth * (b + 2 * c + 2 * d + e) for x, b, c, d, e in zip(qs, vs, v2, v3, v4)]),
            np.array([x + sixth * (b + 2 * c + 2 * d + e) for x, b, c, d, e in zip(vs, a1, a2, a3, a4)]))


def _floats(values: object) -> list[float] | tuple[float, ...]:
    """An acceleration as Python floats (an array's tolist, or the sequence itself)."""
    return values.tolist() if isinstance(values, np.ndarray) else values
