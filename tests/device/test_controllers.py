"""device.controllers: the tracking controller's law written out by hand at seeded states (the
sample at t[0] + s, rounded; the last one after the end; exact), its gains, and a trajectory
whose times do not start at 0."""

import numpy as np

from phantom_pin.device.controllers import KD, KP, tracking

RATE = 500.0


def _trajectory(n=11, start=3.0, seed=13):
    rng = np.random.default_rng(seed)
    t = start + np.arange(n) / RATE
    return t, rng.normal(size=(n, 3)), rng.normal(size=(n, 3)), rng.normal(size=(n, 3))


def test_the_law_at_each_sample_and_between():
    """At s = k / rate (and within half a sample of it) the torque is tau[k] + KP (theta[k] - q)
    + KD (dtheta[k] - v), exactly; simulate's time starts at 0 whatever t[0] is."""
    t, theta, dtheta, tau = _trajectory()
    follow = tracking(t, theta, dtheta, tau)
    rng = np.random.default_rng(14)
    for k in range(len(t)):
        for s in (k / RATE, (k + 0.4) / RATE, (k - 0.4) / RATE if k else 0.0):
            q, v = rng.normal(size=3), rng.normal(size=3)
            expected = tau[k] + KP * (theta[k] - q) + KD * (dtheta[k] - v)
            np.testing.assert_array_equal(follow(s, q, v), expected)
    assert (KP, KD) == (5.0, 0.05)


def test_after_the_end_it_holds_the_last_sample_and_gains_are_its_own():
    t, theta, dtheta, tau = _trajectory()
    q, v = np.full(3, 0.1), np.full(3, -0.2)
    follow = tracking(t, theta, dtheta, tau, kp=2.0, kd=0.5)
    np.testing.assert_array_equal(follow(10.0, q, v), tau[-1] + 2.0 * (theta[-1] - q) + 0.5 * (dtheta[-1] - v))
    # at the trajectory's own state the feedback vanishes: the feed-forward alone
    np.testing.assert_array_equal(follow(3 / RATE, theta[3], dtheta[3]), tau[3])
