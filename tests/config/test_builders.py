"""A configuration's sections built from its files (config/builders.py): the report's lengths,
masses, inertias, gravity and ratios are the printed numbers; coupled stops that leave no posture
are refused; a motor's data sheet is consistent with itself (torque = torque constant x current,
continuous below stall), against the maxon RE 25 data sheet's own arithmetic."""


import pytest
import yaml

from phantom_pin import Device, ParameterFileError, Phantom, config, describe
from phantom_pin.config.builders import MOTOR_TOLERANCE

#: Section 3 of the report, typed from its text: equation number and printed value (SI).
PRINTED = {"l1": (29, 0.215), "l2": (30, 0.170), "l3": (31, 0.0325), "l5": (63, -36.8e-3), "l6": (73, 52.7e-3),
           "ma": (38, 0.0202), "Iaxx": (40, 0.4864e-4), "Iayy": (41, 0.001843e-4), "Iazz": (42, 0.4864e-4),
           "mc": (49, 0.0249), "Icxx": (51, 0.959e-4), "Icyy": (52, 0.959e-4), "Iczz": (53, 0.0051e-4),
           "mbe": (58, 0.2359), "Ibexx": (60, 11.09e-4), "Ibeyy": (61, 10.06e-4), "Ibezz": (62, 0.591e-4),
           "mdf": (68, 0.1906), "Idfxx": (70, 7.11e-4), "Idfyy": (71, 0.629e-4), "Idfzz": (72, 6.246e-4),
           "Ibaseyy": (75, 11.87e-4)}


@pytest.mark.parametrize("name", sorted(PRINTED))
def test_every_shipped_length_mass_and_inertia_is_the_report_number(name):
    """Each to 1e-12 relative (the YAML may write 36.8 mm as -0.0368)."""
    equation, printed = PRINTED[name]
    assert getattr(config.read().report, name) == pytest.approx(printed, rel=1e-12), f"eq. {equation}"


def test_shipped_gravity_and_ratios_are_the_report_numbers():
    """g = 9.81 (appendix), ratios 13.3 (section 3.5.1) and 11.6 (footnotes of eqs 60, 70)."""
    c = config.read()
    assert c.actuation.ratios == (13.3, 11.6, 11.6) and c.report.g == c.gravity == 9.81


@pytest.mark.parametrize("forward, backward, message", [
    (-1.0, -1.0, "must be positive"),  # an empty interval
    (-6.0, 6.5, "leave no posture in the box"),  # -6.5 <= theta2 - theta3 <= -6 rad
    (3.0, -2.7, "leave no posture in the box"),  # 2.7 <= theta2 - theta3 <= 3 rad
])
def test_coupled_stops_that_leave_no_posture_are_refused(folder, forward, backward, message):
    """Before: random_states looped for ever (phantom-pin check hung) and the MJCF's tendon
    range was written inverted. theta2 - theta3 spans -1.466 - 3.037 .. 2.077 + 0.506 rad
    over the URDF's box and -2.164 - 3.735 .. 2.583 rad over the device's stops."""
    limits = folder / "joint_limits.yaml"
    text = limits.read_text()
    for key, value in (("theta2_minus_theta3_max", forward), ("theta3_minus_theta2_max", backward)):
        line = next(line for line in text.splitlines() if line.strip().startswith(key + ":"))
        text = text.replace(line, f"  {key}: {value}")
    limits.write_text(text)
    for call in (config.read, Phantom.from_folder, lambda f: Device(Phantom.from_folder(f)), describe):
        with pytest.raises(ParameterFileError, match=f"joint_limits.yaml: .*{message}"):
            call(folder)
    with pytest.raises(ParameterFileError, match=f"after the overrides, .*{message}"):  # as overrides
        config.read("premium_1_5", {"stops.theta2_minus_theta3_max": forward,
                                    "stops.theta3_minus_theta2_max": backward})


@pytest.mark.parametrize("name", [name for name in config.models() if config.read(name).actuation.motor])
def test_the_shipped_motors_agree_with_their_own_data_sheet(name):
    """maxon RE 25 118743: 23.4 mN m/A x 1.24 A = 29.0 mN m against the nominal 28.6 (1.5 %: the
    no-load current makes no torque), x 5.5 A = 128.7 mN m against the stall 129 (0.2 %)."""
    motor = config.read(name).actuation.motor
    assert abs(motor.torque_constant * motor.max_continuous_current / motor.max_continuous_torque - 1) < 0.02
    assert abs(motor.torque_constant * motor.stall_current / motor.stall_torque - 1) < 0.005
    assert MOTOR_TOLERANCE > 0.02


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
