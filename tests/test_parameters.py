"""Malformed parameter files raise ParameterFileError naming the file and the key."""

import dataclasses
import shutil

import pytest

from phantom_pin import ParameterFileError, Phantom, load_parameters
from phantom_pin.description import generate_urdf
from phantom_pin.parameters import read_overrides, write_overridden
from phantom_pin.paths import CONFIG_DIR


@pytest.fixture()
def config(tmp_path):
    shutil.copytree(CONFIG_DIR, tmp_path / "config")
    return tmp_path / "config"


def test_shipped_parameters_are_the_report_numbers():
    p = load_parameters()
    assert (p.l1, p.l2, p.l3, p.l5, p.l6) == (0.215, 0.170, 0.0325, -0.0368, 0.0527)
    assert (p.ma, p.mc, p.mbe, p.mdf) == (0.0202, 0.0249, 0.2359, 0.1906)
    assert (p.Ibexx, p.Idfxx, p.Ibaseyy) == (11.09e-4, 7.11e-4, 11.87e-4)
    assert p.ratios == (13.3, 11.6, 11.6) and p.g == 9.81


@pytest.mark.parametrize("file, old, new, message", [
    ("kinematics.yaml", "l1: 0.215", "l1: -0.215", "l1 must be positive"),
    ("kinematics.yaml", "l2: 0.170", "l2: abc", "l2 must be a finite number"),
    ("physical_parameters.yaml", "  mass: 0.0202", "  mass_typo: 0.0202", "missing key segment_a.mass"),
    ("joint_limits.yaml", "joint2: {lower: -0.3", "joint2: {lower: 3.0", "joint2.lower must be below"),
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
