"""Malformed parameter files raise ParameterFileError naming the file and the key."""

import shutil

import pytest

from phantom_pin import ParameterFileError, Phantom, load_parameters
from phantom_pin.description import generate_urdf
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
