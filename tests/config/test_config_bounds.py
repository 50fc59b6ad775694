"""Bounds that keep a configuration computable: every number's magnitude (SI units), the MJCF's
timestep, and a motor's data sheet consistent with itself (torque = torque constant x current,
continuous below stall). Against the maxon RE 25 data sheet's own arithmetic and MuJoCo."""

import re

import mujoco
import numpy as np
import pytest
import yaml

from phantom_pin import ParameterFileError, config, describe
from phantom_pin.cli import main
from phantom_pin.config.builders import MOTOR_TOLERANCE
from phantom_pin.config.reader import MAX_MAGNITUDE


@pytest.mark.parametrize("overrides, message", [
    ({"l1": 1e308}, "l1 must be at most 1e+06 in magnitude (SI units), got 1e+308"),
    ({"segment_a.mass": 1e300}, "segment_a.mass must be at most 1e+06 in magnitude"),
    ({"mjcf.timestep": 1.0}, "timestep must be 1e-06 to 0.01 s, got 1.0"),
    ({"mjcf.timestep": 1e-7}, "timestep must be 1e-06 to 0.01 s"),
    ({"actuation.motor.max_continuous_torque": 0.5}, "max_continuous_torque 0.5 N m must be below stall_torque"),
    ({"actuation.motor.max_continuous_current": 6.0}, "max_continuous_current 6 A must be below stall_current"),
    ({"actuation.motor.torque_constant": 0.03}, "is not torque_constant x max_continuous_current"),
    ({"actuation.motor.stall_torque": 0.2}, "stall_torque 0.2 N m is not torque_constant x stall_current"),
])
def test_out_of_scale_or_inconsistent_numbers_are_refused_naming_the_key(overrides, message):
    """Before: l1 = 1e308 raised OverflowError in every command, mass 1e300 and a 1 s timestep
    wrote an MJCF that went NaN on MuJoCo's first step, and a continuous torque of 0.5 N m (17x
    the data sheet's, above the 129 mN m stall) became the MJCF's ctrlrange."""
    with pytest.raises(ParameterFileError, match="after the overrides") as error:
        describe("premium_1_5", overrides=overrides)
    assert message in str(error.value)


def test_the_cli_says_it_in_one_line(capsys):
    assert main(["info", "--set", "l1=1e308"]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1 and "l1 must be at most 1e+06" in err


@pytest.mark.parametrize("name", [name for name in config.models() if config.read(name).actuation.motor])
def test_the_shipped_motors_agree_with_their_own_data_sheet(name):
    """maxon RE 25 118743: 23.4 mN m/A x 1.24 A = 29.0 mN m against the nominal 28.6 (1.5 %: the
    no-load current makes no torque), x 5.5 A = 128.7 mN m against the stall 129 (0.2 %)."""
    motor = config.read(name).actuation.motor
    assert abs(motor.torque_constant * motor.max_continuous_current / motor.max_continuous_torque - 1) < 0.02
    assert abs(motor.torque_constant * motor.stall_current / motor.stall_torque - 1) < 0.005
    assert MOTOR_TOLERANCE > 0.02


def test_the_largest_accepted_scale_still_steps_in_mujoco():
    """A 1e6 kg segment and the longest timestep accepted, each alone: MuJoCo's first hundred
    steps stay finite (before, 1e300 kg or a 1 s step was NaN on the first)."""
    for overrides in ({"segment_a.mass": MAX_MAGNITUDE}, {"mjcf.timestep": 0.01}):
        model = mujoco.MjModel.from_xml_string(describe("premium_1_5", overrides=overrides).mjcf)
        data = mujoco.MjData(model)
        for _ in range(100):
            mujoco.mj_step(model, data)
        assert np.isfinite(data.qpos).all() and np.isfinite(data.qvel).all()


@pytest.mark.parametrize("source, key, value, message", [
    ("touch", "segment_df.com", -1e7, "segment_df.com must be at most 1e+06 in magnitude (SI units), got -10000000.0"),
    ("premium_1_5", "housing.com.2", -1e300, "housing.com must be a list of 3 finite numbers of magnitude at most "
                                             "1e+06, got [0, 0, -1e+300]"),
    ("premium_1_5_cad", "links.forearm_link.com.0", 1e300, "links.forearm_link.com must be a list of 3 finite "
                                                           "numbers of magnitude at most 1e+06, got [1e+300, "),
])
def test_the_magnitude_bound_holds_for_negative_numbers_and_list_items(source, key, value, message):
    """The 1e6 bound on a number's magnitude holds for negative numbers and for each item of a
    list (com.0 = 1e300 would give NaN gravity), refused naming the key."""
    with pytest.raises(ParameterFileError, match=re.escape(message)):
        config.read(source, {key: value})


def test_a_continuous_torque_equal_to_the_stall_torque_is_refused():
    """A motor's continuous torque must be strictly below its stall torque (a winding cannot run
    at stall): equal to the data sheet's 129 mN m (read with PyYAML) it is refused; just below it
    is a motor."""
    stated = yaml.safe_load((config.MODELS["premium_1_5"].config / "actuation.yaml").read_text())["motor"]
    key = "actuation.motor.max_continuous_torque"
    current = {"actuation.motor.max_continuous_current": 0.998 * stated["stall_current"]}  # Kt I = the torque
    with pytest.raises(ParameterFileError, match=f"max_continuous_torque {stated['stall_torque']:g} N m must be "
                                                 f"below stall_torque {stated['stall_torque']:g} N m"):
        config.read("premium_1_5", {key: stated["stall_torque"], **current})
    below = config.read("premium_1_5", {key: stated["stall_torque"] * (1 - 1e-9), **current})
    assert below.actuation.motor.max_continuous_torque < stated["stall_torque"]
