"""The one integrator: a classical fourth-order Runge-Kutta step of the arm's second-order
system (three joints)."""

from __future__ import annotations

from collections.abc import Callable, Sequence

Vector = Sequence[float]


def rk4_step(acceleration: Callable[[Vector, Vector], Vector], q: Vector, v: Vector,
             h: float) -> tuple[list[float], list[float]]:
    """(q, v) after one classical RK4 step of h (s) of q'' = acceleration(q, v), positions
    q (rad), rates v (rad/s) and accelerations (rad/s^2) of the three joints, as new lists;
    the inputs are not changed. Unrolled on Python floats: for the arm's 3-vectors NumPy's
    per-operation cost, and then a loop's, exceeded the acceleration's
    (benchmarks/bench_plants.py). ``acceleration`` gets lists and returns three floats."""
    half, sixth = 0.5 * h, h / 6.0
    q0, q1, q2 = q
    v0, v1, v2 = v
    a0, a1, a2 = acceleration(q, v)                                       # stage 1 at (q, v)
    u0, u1, u2 = v0 + half * a0, v1 + half * a1, v2 + half * a2          # stage 2's rates
    b0, b1, b2 = acceleration([q0 + half * v0, q1 + half * v1, q2 + half * v2], [u0, u1, u2])
    w0, w1, w2 = v0 + half * b0, v1 + half * b1, v2 + half * b2          # stage 3's rates
    c0, c1, c2 = acceleration([q0 + half * u0, q1 + half * u1, q2 + half * u2], [w0, w1, w2])
    x0, x1, x2 = v0 + h * c0, v1 + h * c1, v2 + h * c2                   # stage 4's rates
    d0, d1, d2 = acceleration([q0 + h * w0, q1 + h * w1, q2 + h * w2], [x0, x1, x2])
    return ([q0 + sixth * (v0 + 2 * (u0 + w0) + x0), q1 + sixth * (v1 + 2 * (u1 + w1) + x1),
             q2 + sixth * (v2 + 2 * (u2 + w2) + x2)],
            [v0 + sixth * (a0 + 2 * (b0 + c0) + d0), v1 + sixth * (a1 + 2 * (b1 + c1) + d1),
             v2 + sixth * (a2 + 2 * (b2 + c2) + d2)])
