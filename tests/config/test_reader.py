"""The checks of the parameter files' numbers (config/reader.py): malformed or non-physical files
raise ParameterFileError naming the file and the key; joint limits within one turn; the bounds that
keep a configuration computable, every number's magnitude (SI units) and the MJCF's timestep,
against MuJoCo."""

import re

import mujoco
import numpy as np
import pytest

from phantom_pin import Device, ParameterFileError, Phantom, config, describe
from phantom_pin.cli import main
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


def test_joint_limits_beyond_one_turn_are_refused(folder):
    limits = folder / "joint_limits.yaml"
    limits.write_text(limits.read_text().replace("joint1: {lower: -1.5707963267948966, upper: 1.5707963267948966}",
                                                 "joint1: {lower: -1.0, upper: 100.0}"))
    with pytest.raises(ParameterFileError, match="joint1.upper must be within one turn"):
        config.read(folder)


@pytest.mark.parametrize("file, old, new, message", [
    ("kinematics.yaml", "l1: 0.215", "l1: -0.215", "l1 must be positive"),
    ("kinematics.yaml", "l2: 0.170", "l2: abc", "l2 must be a finite number"),
    ("physical_parameters.yaml", "  mass: 0.0202", "  mass_typo: 0.0202", "missing key segment_a.mass"),
    ("joint_limits.yaml", "joint2: {lower: -1.4660765716752369", "joint2: {lower: 3.0", "joint2.lower must be below"),
    ("actuation.yaml", "motor:", "motor: [", "not valid YAML"),
    ("actuation.yaml", "viscous: 5.0e-4", "viscous: -5.0e-4", "friction.viscous must not be negative"),
    ("actuation.yaml", "coulomb: 0.01", "coulomb: -0.01", "friction.coulomb must not be negative"),
    ("mjcf.yaml", "integrator: RK4", "integrator: RK5", "integrator must be"),
])
def test_malformed_files_are_named(folder, file, old, new, message):
    """Every consumer reads the same checked Config: describe (URDF, MJCF), Phantom, Device."""
    path = folder / file
    text = path.read_text()
    assert old in text
    path.write_text(text.replace(old, new, 1))
    for call in (config.read, describe, Phantom.from_folder, lambda f: Device(Phantom.from_folder(f))):
        with pytest.raises(ParameterFileError, match=message) as error:
            call(folder)
        assert file in str(error.value)


@pytest.mark.parametrize("value, accepted", [(2 * np.pi - 0.1, True), (2 * np.pi + 0.1, False)])
def test_a_joint_limit_is_within_one_turn(value, accepted):
    overrides = {"joint_limits.joint3.upper": value, "joint_limits.stops.joint3.upper": value}
    if accepted:
        assert config.read("premium_1_5", overrides).limits.upper[2] == value
    else:
        with pytest.raises(ParameterFileError, match=r"joint3.upper must be within one turn"):
            config.read("premium_1_5", overrides)


@pytest.mark.parametrize("overrides, message", [
    ({"joint_limits.joint1.lower": 0.5, "joint_limits.joint1.upper": 0.5}, "joint1.lower must be below joint1.upper"),
    ({"joint_limits.stops.joint2.lower": 1.0, "joint_limits.stops.joint2.upper": 1.0},
     "stops.joint2.lower must be below stops.joint2.upper"),
    ({"stops.damping": -0.1}, "stops.damping must not be negative"),
    ({"actuation.friction.coulomb": -0.01}, "friction.coulomb must not be negative"),
])
def test_empty_intervals_and_negative_dissipation_are_refused(overrides, message):
    with pytest.raises(ParameterFileError, match=message):
        config.read("premium_1_5", overrides)
