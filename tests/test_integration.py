"""phantom_pin._integration: the RK4 step on harmonic oscillators, whose exact solution is known
(q = A cos(w t) + B sin(w t)): its one-step result is the exact solution's Taylor series to the
fourth order, its error over a fixed time falls 16-fold when the step halves, and it leaves its
inputs unchanged."""

import math

import numpy as np

from phantom_pin._integration import rk4_step

OMEGA = (1.0, 2.0, 3.0)          # rad/s, one per joint
DAMPING = (0.0, 0.1, 0.0)        # 1/s on joint 2: the rates enter the acceleration too


def _oscillators(damping=DAMPING):
    """q'' = -w^2 q - 2 c q' per joint."""
    return lambda q, v: [-(w * w) * x - 2 * c * u for w, c, x, u in zip(OMEGA, damping, q, v)]


_acceleration = _oscillators()


def _exact(q0, v0, t):
    """The damped oscillator's exact solution (underdamped: c < w)."""
    q, v = [], []
    for w, c, x, u in zip(OMEGA, DAMPING, q0, v0):
        wd = math.sqrt(w * w - c * c)
        a, b = x, (u + c * x) / wd
        e, cs, sn = math.exp(-c * t), math.cos(wd * t), math.sin(wd * t)
        q.append(e * (a * cs + b * sn))
        v.append(e * (-c * (a * cs + b * sn) + wd * (-a * sn + b * cs)))
    return q, v


def _run(h, steps, q0, v0):
    q, v = q0, v0
    for _ in range(steps):
        q, v = rk4_step(_acceleration, q, v, h)
    return q, v


def test_one_step_is_the_fourth_order_taylor_polynomial():
    """For q'' = -w^2 q (no damping), one RK4 step multiplies (q, v) by the exact rotation's
    Taylor polynomial to degree 4 in w h: q1 = (1 - z^2/2 + z^4/24) q0 + (h - w^2 h^3/6) v0,
    z = w h (within 1e-15 of it)."""
    q0, v0, h = [0.3, -0.2, 0.1], [0.5, 0.0, -0.7], 0.1
    q, v = rk4_step(_oscillators((0.0, 0.0, 0.0)), q0, v0, h)
    for j, w in enumerate(OMEGA):
        z = w * h
        assert abs(q[j] - ((1 - z**2 / 2 + z**4 / 24) * q0[j] + (h - w**2 * h**3 / 6) * v0[j])) < 1e-15
        assert abs(v[j] - ((1 - z**2 / 2 + z**4 / 24) * v0[j] - w**2 * (h - w**2 * h**3 / 6) * q0[j])) < 1e-15


def test_the_error_falls_16_fold_when_the_step_halves():
    """Over 1 s, h = 0.02, 0.01, 0.005 s: the global error against the exact solution of the
    damped oscillators falls by 16 +- 1.5 each halving (fourth order), and is below 1e-7 at
    h = 0.01 s."""
    q0, v0 = [0.3, -0.2, 0.1], [0.5, 0.0, -0.7]
    exact = np.concatenate(_exact(q0, v0, 1.0))
    errors = [np.abs(np.concatenate(_run(1.0 / n, n, q0, v0)) - exact).max() for n in (50, 100, 200)]
    assert errors[1] < 1e-7
    for coarse, fine in zip(errors, errors[1:]):
        assert 14.5 < coarse / fine < 17.5, errors


def test_the_inputs_are_left_unchanged_and_new_lists_returned():
    q0, v0 = [0.3, -0.2, 0.1], [0.5, 0.0, -0.7]
    q, v = rk4_step(_acceleration, q0, v0, 0.01)
    assert q0 == [0.3, -0.2, 0.1] and v0 == [0.5, 0.0, -0.7]
    assert isinstance(q, list) and isinstance(v, list) and q is not q0 and v is not v0
    assert rk4_step(_acceleration, q0, v0, 0.0) == (q0, v0)
