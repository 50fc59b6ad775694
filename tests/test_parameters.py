"""Malformed parameter files raise ParameterFileError naming the file and the key."""

import dataclasses
import shutil

import numpy as np
import pytest

from phantom_pin import InvalidInputError, ParameterFileError, Phantom, load_parameters
from phantom_pin.description import generate_urdf
from phantom_pin.device.parameters import load_device_parameters
from phantom_pin.parameters import parameters_from, random_states, read_config, read_overrides, write_overridden
from phantom_pin.paths import CONFIG_DIR


@pytest.fixture()
def config(tmp_path):
    shutil.copytree(CONFIG_DIR, tmp_path / "config")
    return tmp_path / "config"


#: Section 3 of the report, typed from its text: equation number and printed value (SI).
REPORT = {"l1": (29, 0.215), "l2": (30, 0.170), "l3": (31, 0.0325), "l5": (63, -36.8e-3), "l6": (73, 52.7e-3),
          "ma": (38, 0.0202), "Iaxx": (40, 0.4864e-4), "Iayy": (41, 0.001843e-4), "Iazz": (42, 0.4864e-4),
          "mc": (49, 0.0249), "Icxx": (51, 0.959e-4), "Icyy": (52, 0.959e-4), "Iczz": (53, 0.0051e-4),
          "mbe": (58, 0.2359), "Ibexx": (60, 11.09e-4), "Ibeyy": (61, 10.06e-4), "Ibezz": (62, 0.591e-4),
          "mdf": (68, 0.1906), "Idfxx": (70, 7.11e-4), "Idfyy": (71, 0.629e-4), "Idfzz": (72, 6.246e-4),
          "Ibaseyy": (75, 11.87e-4)}


@pytest.mark.parametrize("name", sorted(REPORT))
def test_every_shipped_length_mass_and_inertia_is_the_report_number(name):
    """Each to 1e-12 relative (the YAML may write 36.8 mm as -0.0368)."""
    equation, printed = REPORT[name]
    assert getattr(load_parameters(), name) == pytest.approx(printed, rel=1e-12), f"eq. {equation}"


def test_shipped_gravity_and_ratios_are_the_report_numbers():
    """g = 9.81 (appendix), ratios 13.3 (section 3.5.1) and 11.6 (footnotes of eqs 60, 70)."""
    p = load_parameters()
    assert p.ratios == (13.3, 11.6, 11.6) and p.g == 9.81


def test_yaml_numbers_without_a_dot_are_numbers(config):
    """PyYAML reads 11e-7 and 2.0e6 as strings (YAML 1.1); the parameter files read them as
    numbers, and xacro sees the same numbers (the rotor inertia reaches the armature)."""
    actuation = config / "actuation.yaml"
    text = actuation.read_text()
    rotor = next(line for line in text.splitlines() if "rotor_inertia:" in line)
    actuation.write_text(text.replace(rotor, "  rotor_inertia: 11e-7"))
    assert load_parameters(config).rotor_inertia == 1.1e-6
    ratios = load_parameters(config).ratios
    np.testing.assert_allclose(Phantom(config).model.armature, [1.1e-6 * r**2 for r in ratios], rtol=1e-12)
    overrides = config.parent / "params.yaml"
    overrides.write_text("l1: 21e-2\nsegment_a.mass: +2E-2\n")
    assert read_overrides(overrides) == {"l1": 0.21, "segment_a.mass": 0.02}


def test_binary_and_malformed_files_raise_one_line_naming_the_file(config, tmp_path):
    (config / "kinematics.yaml").write_bytes(bytes(range(128, 256)))
    with pytest.raises(ParameterFileError, match="kinematics.yaml: not a text file") as error:
        load_parameters(config)
    assert "\n" not in str(error.value)
    (config / "kinematics.yaml").write_text("l1: 0.215\nl2: [0.17\nl3: 0.0325\n")
    with pytest.raises(ParameterFileError, match=r"kinematics.yaml: not valid YAML at line \d+") as error:
        load_parameters(config)
    assert "\n" not in str(error.value)


def test_joint_limits_beyond_one_turn_are_refused(config):
    limits = config / "joint_limits.yaml"
    limits.write_text(limits.read_text().replace("joint1: {lower: -1.5707963267948966, upper: 1.5707963267948966}",
                                                 "joint1: {lower: -1.0, upper: 1.0e308}"))
    with pytest.raises(ParameterFileError, match="joint1.upper must be within one turn"):
        load_parameters(config)


@pytest.mark.parametrize("forward, backward, message", [
    (-1.0, -1.0, "must be positive"),  # an empty interval
    (-6.0, 6.5, "leave no posture in the box"),  # -6.5 <= theta2 - theta3 <= -6 rad
    (3.0, -2.7, "leave no posture in the box"),  # 2.7 <= theta2 - theta3 <= 3 rad
])
def test_coupled_stops_that_leave_no_posture_are_refused(config, forward, backward, message):
    """Before: random_states looped for ever (phantom-pin check hung) and the MJCF's tendon
    range was written inverted. theta2 - theta3 spans -1.466 - 3.037 .. 2.077 + 0.506 rad
    over the URDF's box and -2.164 - 3.735 .. 2.583 rad over the device's stops."""
    limits = config / "joint_limits.yaml"
    text = limits.read_text()
    for key, value in (("theta2_minus_theta3_max", forward), ("theta3_minus_theta2_max", backward)):
        line = next(line for line in text.splitlines() if line.strip().startswith(key + ":"))
        text = text.replace(line, f"  {key}: {value}")
    limits.write_text(text)
    for call in (load_parameters, Phantom, load_device_parameters, lambda c: generate_urdf(config_dir=c)):
        with pytest.raises(ParameterFileError, match=f"joint_limits.yaml: .*{message}"):
            call(config)
    with pytest.raises(ParameterFileError, match=f"after the overrides, .*{message}"):  # as overrides
        parameters_from(read_config(CONFIG_DIR, {"stops.theta2_minus_theta3_max": forward,
                                                 "stops.theta3_minus_theta2_max": backward}))


def test_random_states_refuses_a_sliver_instead_of_looping():
    """Stops that keep about 4e-7 of the box (a corner triangle 3 mrad wide): one line, no hang."""
    params = dataclasses.replace(load_parameters(), coupled=(-4.5, 5.0))
    with pytest.raises(ParameterFileError, match="coupled stops .* keep too little of the joint box"):
        random_states(params, 100, seed=0)
    theta = random_states(load_parameters(), 2000, seed=0)[0]  # the shipped stops: inside
    assert np.all(theta[:, 1] - theta[:, 2] <= load_parameters().coupled[0])


@pytest.mark.parametrize("call", [Phantom, load_parameters, lambda c: generate_urdf(config_dir=c)])
def test_config_dir_must_be_a_path(call):
    with pytest.raises(InvalidInputError, match="config_dir: expected a path"):
        call(123)


@pytest.mark.parametrize("file, old, new, message", [
    ("kinematics.yaml", "l1: 0.215", "l1: -0.215", "l1 must be positive"),
    ("kinematics.yaml", "l2: 0.170", "l2: abc", "l2 must be a finite number"),
    ("physical_parameters.yaml", "  mass: 0.0202", "  mass_typo: 0.0202", "missing key segment_a.mass"),
    ("joint_limits.yaml", "joint2: {lower: -1.4660765716752369", "joint2: {lower: 3.0", "joint2.lower must be below"),
    ("actuation.yaml", "motor:", "motor: [", "not valid YAML"),
])
def test_malformed_files_are_named(config, file, old, new, message):
    path = config / file
    text = path.read_text()
    assert old in text
    path.write_text(text.replace(old, new, 1))
    for call in (load_parameters, lambda c: generate_urdf(config_dir=c), Phantom):
        with pytest.raises(ParameterFileError, match=message) as error:
            call(config)
        assert file in str(error.value)


def test_missing_file(tmp_path):
    with pytest.raises(ParameterFileError, match="cannot read"):
        load_parameters(tmp_path)


def test_overrides_nested_dotted_and_qualified_keys_are_the_same(tmp_path):
    nested, dotted = tmp_path / "nested.yaml", tmp_path / "dotted.yaml"
    nested.write_text("segment_a: {inertia: {xx: 5.0e-5}}\nactuation: {motor: {rotor_inertia: 2.0e-6}}\n")
    dotted.write_text("segment_a.inertia.xx: 5.0e-5\nactuation.motor.rotor_inertia: 2.0e-6\n")
    assert read_overrides(nested) == read_overrides(dotted) == {
        "segment_a.inertia.xx": 5.0e-5, "actuation.motor.rotor_inertia": 2.0e-6}
    folder = tmp_path / "config"
    folder.mkdir()
    p = load_parameters(write_overridden(read_overrides(nested), folder))
    assert (p.Iaxx, p.rotor_inertia) == (5.0e-5, 2.0e-6)
    assert dataclasses.replace(p, Iaxx=load_parameters().Iaxx, rotor_inertia=load_parameters().rotor_inertia) \
        == load_parameters()  # nothing else changed


def test_malformed_override_file_raises_naming_the_file(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("- l1\n- 0.2\n")
    with pytest.raises(ParameterFileError, match="bad.yaml: expected a mapping"):
        read_overrides(bad)
