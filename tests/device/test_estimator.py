"""The servo loop's rate and acceleration estimates (phantom_pin.device.estimator) against the
closed-form response of a first-order low-pass of backward differences: a step of rate reaches
1 - (1 - alpha)^k of it after k samples, a ramp's rate and a parabola's acceleration converge to
the exact ones; stamped samples at a fixed period give the fixed-rate estimates, and a burst of
one stamp steps nothing."""

import math

import numpy as np
import pytest

from phantom_pin.device.estimator import Estimator
from phantom_pin.exceptions import InvalidInputError


def test_the_rate_of_a_ramp_follows_the_filters_closed_form():
    estimator, v = Estimator(1000.0, 20.0), np.array([0.3, -0.2, 0.1])
    alpha = 1 - math.exp(-2 * math.pi * 20.0 / 1000.0)
    for k in range(400):
        rate, _ = estimator.update(v * k / 1000.0)
        assert np.allclose(rate, v * (1 - (1 - alpha) ** k), rtol=1e-9, atol=1e-15)
    assert np.allclose(rate, v, rtol=1e-9)


def test_the_acceleration_of_a_parabola_converges_to_it():
    estimator, a = Estimator(1000.0, 20.0), np.array([2.0, -1.0, 0.5])
    for k in range(1200):
        rate, acceleration = estimator.update(0.5 * a * (k / 1000.0) ** 2)
    assert np.allclose(acceleration, a, rtol=1e-7)


def test_stamps_at_a_fixed_period_are_the_fixed_rate_and_a_burst_steps_nothing():
    fixed, stamped = Estimator(), Estimator()
    rng = np.random.default_rng(3)
    for k in range(200):
        theta = rng.normal(0, 0.1, 3)
        expected = fixed.update(theta)
        got = stamped.update_at(theta, k / 1000.0)
        assert np.allclose(got[0], expected[0], rtol=1e-12, atol=1e-12)
        assert np.allclose(got[1], expected[1], rtol=1e-9, atol=1e-9)
    before = stamped.rate.copy()
    stamped.update_at(np.ones(3), 199 / 1000.0)          # the same stamp again: no step
    assert np.array_equal(stamped.rate, before)
    for bad in (None, math.nan):
        with pytest.raises(InvalidInputError) as error:
            stamped.update_at(np.zeros(3), bad)
        assert error.value.argument == "time"
    for kwargs, argument in (({"rate": 0.0}, "rate"), ({"cutoff": -1.0}, "cutoff"), ({"cutoff": 600.0}, "cutoff")):
        with pytest.raises(InvalidInputError) as error:
            Estimator(**kwargs)
        assert error.value.argument == argument
