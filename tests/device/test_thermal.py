"""The motors' two limits over time (phantom_pin.device.thermal.TorqueBudget) against the
winding's heat law: e' = (tau^2 - e) / T discretised exactly per period, the continuous rating
the steady-state bound of e."""

import math

import numpy as np
import pytest

from phantom_pin import Device
from phantom_pin.config import read
from phantom_pin.device.thermal import TorqueBudget
from phantom_pin.exceptions import InvalidInputError


def test_a_stall_torque_lasts_what_the_heat_law_says_then_the_rating_holds():
    """From cold, a demand above the peak gets the peak for -T ln(1 - tau_c^2 / tau_p^2) (the
    exponential average reaching tau_c^2; within one period of 1 ms), then the continuous torque;
    after 60 s the winding's mean square is tau_c^2 (1e-9); a 30 s rest gives the peak back."""
    motor = read("premium_1_5").actuation.motor
    budget = TorqueBudget(Device.from_model("premium_1_5"))
    demand = 2 * budget.peak
    ticks = 0
    while budget.clip(demand)[1] >= budget.peak[1] * (1 - 1e-12):
        ticks += 1
    ratio = motor.max_continuous_torque / motor.stall_torque
    assert abs(ticks * 1e-3 - (-motor.thermal_time_constant * math.log(1 - ratio ** 2))) <= 1e-3
    for _ in range(60000):
        given = budget.clip(demand)
    assert np.allclose(given, budget.continuous, rtol=1e-9)
    assert np.allclose(np.sqrt(budget.mean_square), budget.continuous, rtol=1e-9)
    for _ in range(30000):
        budget.clip(np.zeros(3))
    assert np.allclose(budget.clip(demand), budget.peak)


def test_a_force_keeps_its_direction_and_a_model_without_motors_has_one_limit():
    touch = TorqueBudget(Device.from_model("touch"))
    assert np.array_equal(touch.peak, touch.continuous)
    tau = np.array([3.0, -0.1, 0.2]) * touch.peak
    s = touch.scale(tau)
    assert math.isclose(s, 1 / 3) and np.all(np.abs(s * tau) <= touch.peak * (1 + 1e-12))
    for _ in range(100):
        assert np.allclose(touch.clip(2 * touch.peak), touch.peak)
    with pytest.raises(InvalidInputError) as error:
        TorqueBudget(Device.from_model("touch"), period=0.0)
    assert error.value.argument == "period"
