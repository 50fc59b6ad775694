"""The parameter files and the overrides (config/files.py): YAML numbers without a dot are
numbers, binary, malformed and missing files raise one line naming the file, nested, dotted and
qualified override keys are the same."""

import dataclasses

import numpy as np
import pytest

from phantom_pin import ParameterFileError, Phantom, config
from phantom_pin.config import read_overrides


def test_yaml_numbers_without_a_dot_are_numbers(folder):
    """PyYAML reads 11e-7 and 2.0e6 as strings (YAML 1.1); the parameter files read them as
    numbers, and xacro sees the same numbers (the rotor inertia reaches the armature)."""
    actuation = folder / "actuation.yaml"
    text = actuation.read_text()
    rotor = next(line for line in text.splitlines() if "rotor_inertia:" in line)
    actuation.write_text(text.replace(rotor, "  rotor_inertia: 11e-7"))
    c = config.read(folder)
    assert c.actuation.motor.rotor_inertia == 1.1e-6
    np.testing.assert_allclose(Phantom.from_folder(folder).model.armature, [1.1e-6 * r**2 for r in c.actuation.ratios],
                               rtol=1e-12)
    overrides = folder.parent / "params.yaml"
    overrides.write_text("l1: 21e-2\nsegment_a.mass: +2E-2\n")
    assert read_overrides(overrides) == {"l1": 0.21, "segment_a.mass": 0.02}


def test_binary_and_malformed_files_raise_one_line_naming_the_file(folder):
    (folder / "kinematics.yaml").write_bytes(bytes(range(128, 256)))
    with pytest.raises(ParameterFileError, match="kinematics.yaml: not a text file") as error:
        config.read(folder)
    assert "\n" not in str(error.value)
    (folder / "kinematics.yaml").write_text("l1: 0.215\nl2: [0.17\nl3: 0.0325\n")
    with pytest.raises(ParameterFileError, match=r"kinematics.yaml: not valid YAML at line \d+") as error:
        config.read(folder)
    assert "\n" not in str(error.value)


def test_missing_file(tmp_path):
    with pytest.raises(ParameterFileError, match="not a configuration folder"):   # an empty folder
        config.read(tmp_path)
    (tmp_path / "kinematics.yaml").write_text("l1: 0.2\nl2: 0.2\nl3: 0.03\n")
    with pytest.raises(ParameterFileError, match="physical_parameters.yaml: cannot read"):
        config.read(tmp_path)


def test_overrides_nested_dotted_and_qualified_keys_are_the_same(tmp_path):
    nested, dotted = tmp_path / "nested.yaml", tmp_path / "dotted.yaml"
    nested.write_text("segment_a: {inertia: {xx: 4.87e-5}}\nactuation: {motor: {rotor_inertia: 1.05e-6}}\n")
    dotted.write_text("segment_a.inertia.xx: 4.87e-5\nactuation.motor.rotor_inertia: 1.05e-6\n")
    assert read_overrides(nested) == read_overrides(dotted) == {
        "segment_a.inertia.xx": 4.87e-5, "actuation.motor.rotor_inertia": 1.05e-6}
    changed, shipped_config = config.read("premium_1_5", read_overrides(nested)), config.read()
    assert (changed.report.Iaxx, changed.actuation.motor.rotor_inertia) == (4.87e-5, 1.05e-6)
    unchanged = dataclasses.replace(
        changed, overridden=False, report=dataclasses.replace(changed.report, Iaxx=shipped_config.report.Iaxx),
        actuation=dataclasses.replace(changed.actuation, motor=shipped_config.actuation.motor),
        links=shipped_config.links, sources=shipped_config.sources)  # the motor's says what changed
    assert unchanged == shipped_config  # nothing else changed


def test_malformed_override_file_raises_naming_the_file(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("- l1\n- 0.2\n")
    with pytest.raises(ParameterFileError, match="bad.yaml: expected a mapping"):
        read_overrides(bad)
