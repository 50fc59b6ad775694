"""identification.verdict.overlays: the overlay's keys round-tripped through describe(overrides=...)
(the friction per joint and the bodies read back from the Config, the model and lengths it is
valid with), a non-physical overlay refused before anything is written, its YAML read back by
PyYAML, and the refusals naming their argument."""

from types import SimpleNamespace

import numpy as np
import pytest
import yaml

from helpers import CONFIG
from phantom_pin import InvalidInputError, ParameterFileError, config, describe
from phantom_pin.identification.verdict import overlays

FRICTION = np.array([1e-4, 2e-4, 3e-4, 0.011, 0.012, 0.013])


def test_the_keys_round_trip_through_describe():
    """identified_keys with the identified friction and a body's mass: describe() of the keys
    gives the friction per joint (exactly) and the mass; the keys carry the model's name and
    lengths first; given's body and friction keys are dropped, its other keys kept."""
    friction = overlays.friction_keys(SimpleNamespace(x=np.concatenate([np.zeros(20), FRICTION])))
    assert tuple(friction) == overlays.FRICTION_KEYS
    given = {"segment_a.mass": 1.0, "actuation.friction.viscous": 0.5, "friction.coulomb": 0.5,
             "gravity": 9.80665}
    keys = overlays.identified_keys({"segment_c.mass": 1.1 * CONFIG.report.mc}, given, CONFIG, friction)
    assert list(keys)[:4] == ["model", "l1", "l2", "l3"] and keys["model"] == "premium_1_5"
    assert (keys["l1"], keys["l2"], keys["l3"]) == (CONFIG.kinematics.l1, CONFIG.kinematics.l2, CONFIG.kinematics.l3)
    assert "segment_a.mass" not in keys and "actuation.friction.viscous" not in keys
    assert "friction.coulomb" not in keys and keys["gravity"] == 9.80665
    read = describe(overrides=keys).config
    assert read.actuation.friction.viscous == tuple(FRICTION[:3])
    assert read.actuation.friction.coulomb == tuple(FRICTION[3:])
    assert read.report.mc == 1.1 * CONFIG.report.mc and read.report.ma == CONFIG.report.ma
    # without friction identified, given's friction stays
    assert overlays.identified_keys({}, given, None, None)["actuation.friction.viscous"] == 0.5


def test_a_non_physical_overlay_and_bad_arguments_are_refused():
    """A negative mass: ParameterFileError before anything is written; a given that is no dict
    names ``given``; overlay of no Fit names ``fit``; write_yaml onto an existing file ``path``."""
    with pytest.raises(ParameterFileError, match="identified parameters not physically valid"):
        overlays.identified_keys({"segment_c.mass": -0.1}, None, CONFIG, None)
    with pytest.raises(InvalidInputError) as refused:
        overlays.identified_keys({}, ["segment_a.mass"], CONFIG, None)
    assert refused.value.argument == "given"
    with pytest.raises(InvalidInputError) as refused:
        overlays.overlay({"segment_a.mass": 1.0})
    assert refused.value.argument == "fit"


def test_the_yaml_text_reads_back(tmp_path):
    """yaml_text: one '# ' line per comment, then keys PyYAML reads back equal (floats exact by
    repr, strings quoted); write_yaml writes it, refuses an existing file naming ``path``, overwrites with force."""
    keys = {"model": "premium_1_5", "l1": 0.215, "actuation.friction.viscous.joint1": 1 / 3,
            "name": "1.5"}                          # a string that reads as a number unless quoted
    text = overlays.yaml_text(["first", "second: with a colon"], keys)
    assert text.splitlines()[:2] == ["# first", "# second: with a colon"]
    assert yaml.safe_load(text) == keys
    path = tmp_path / "fit.yaml"
    overlays.write_yaml(path, text)
    assert path.read_text(encoding="utf-8") == text
    with pytest.raises(InvalidInputError) as refused:
        overlays.write_yaml(path, "x: 1\n")
    assert refused.value.argument == "path" and path.read_text(encoding="utf-8") == text
    overlays.write_yaml(path, "x: 1\n", force=True)
    assert yaml.safe_load(path.read_text(encoding="utf-8")) == {"x": 1}


def test_the_stylus_keys_are_the_gimbals_held_angles():
    """The Touch's stylus held at its configured gimbal angles: gimbal.locked_at.0..2; none for
    the Premium 1.5, which has no stylus gimbal."""
    touch = config.read("touch")
    held = overlays.stylus_keys(touch)
    assert held == {f"gimbal.locked_at.{k}": float(a) for k, a in enumerate(touch.gimbal.locked_at)} and len(held) == 3
    assert overlays.stylus_keys(CONFIG) == {}
