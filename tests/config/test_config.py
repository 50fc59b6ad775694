"""The configuration: read once into a typed, immutable Config; malformed or non-physical
files raise ParameterFileError naming the file and the key; named models."""

import dataclasses
import importlib
import inspect
import pkgutil
import shutil
from pathlib import Path

import numpy as np
import pytest
import yaml

import phantom_pin
from phantom_pin import Device, InvalidInputError, ParameterFileError, Phantom, config, describe
from phantom_pin.config import MODELS, read_overrides
from phantom_pin.config.sampling import random_states
from phantom_pin.description.build import shipped


@pytest.fixture()
def folder(tmp_path):
    shutil.copytree(MODELS["premium_1_5"].config, tmp_path / "config")
    return tmp_path / "config"


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


def test_models_are_named_and_resolve_like_folders():
    assert config.models() == phantom_pin.models() == ["premium_1_5", "premium_1_5_cad", "touch"]
    by_name, by_folder = config.read("premium_1_5"), config.read(MODELS["premium_1_5"].config)
    assert by_name == by_folder and by_name.name == "premium_1_5"
    for call in (config.read, describe, Phantom, Device, phantom_pin.load):
        with pytest.raises(InvalidInputError, match="premium_9"):
            call("premium_9")
    with pytest.raises(InvalidInputError, match="expected a model name"):
        config.read(123)


def test_the_shipped_configuration_cannot_be_changed():
    """Before, shipped().config.data was a mutable dict: a change leaked into every later
    Device() in the process. Now every part is frozen or read-only."""
    c = shipped().config
    with pytest.raises(dataclasses.FrozenInstanceError):
        c.actuation.friction.viscous = 1.0
    with pytest.raises(dataclasses.FrozenInstanceError):
        c.links["forearm_link"].mass = 1.0
    with pytest.raises(TypeError):
        c.links["forearm_link"] = None
    with pytest.raises(TypeError):
        c.visual["colors"]["arm"] = [0, 0, 0, 1]
    with pytest.raises(TypeError):
        c.sources["friction"] = "mine"
    assert Device().config.actuation.friction.viscous == (5.0e-4,) * 3


def _defaults(function):
    try:
        return [p.default for p in inspect.signature(function).parameters.values()]
    except (TypeError, ValueError):
        return []


def test_no_function_below_the_entry_points_defaults_to_a_configuration():
    """Every function takes the Description (or Config) it works on: no parameter below the
    public entry points defaults to a model name, a configuration folder or a Config."""
    entry_points = {"describe", "shipped", "description_of", "read", "resolve", "load", "__init__", "simulate",
                    "default_device", "main"}
    found = []
    for module_info in pkgutil.walk_packages(phantom_pin.__path__, "phantom_pin."):
        module = importlib.import_module(module_info.name)
        for name, item in vars(module).items():
            if getattr(item, "__module__", None) != module.__name__:
                continue
            functions = [(name, item)] if inspect.isfunction(item) else []
            if inspect.isclass(item):
                functions += [(f"{name}.{n}", f) for n, f in vars(item).items() if inspect.isfunction(f)]
            for qualified, function in functions:
                if qualified.split(".")[-1] in entry_points and not qualified.startswith(("Regressor", "Structured")):
                    continue
                for default in _defaults(function):
                    if (isinstance(default, (Path, config.Config)) or default in config.models()
                            or default is config.DEFAULT):
                        found.append(f"{module.__name__}.{qualified}")
    assert not found


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


def test_joint_limits_beyond_one_turn_are_refused(folder):
    limits = folder / "joint_limits.yaml"
    limits.write_text(limits.read_text().replace("joint1: {lower: -1.5707963267948966, upper: 1.5707963267948966}",
                                                 "joint1: {lower: -1.0, upper: 100.0}"))
    with pytest.raises(ParameterFileError, match="joint1.upper must be within one turn"):
        config.read(folder)


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


def test_random_states_refuses_a_sliver_instead_of_looping():
    """Stops that keep about 4e-7 of the box (a corner triangle 3 mrad wide): one line, no hang."""
    limits = config.read().limits
    sliver = dataclasses.replace(limits, stops=dataclasses.replace(
        limits.stops, coupled=config.CoupledStops(-4.5, 5.0)))
    with pytest.raises(ParameterFileError, match="coupled stops .* keep too little of the joint box"):
        random_states(sliver, 100, seed=0)
    theta = random_states(limits, 2000, seed=0)[0]  # the shipped stops: inside
    assert np.all(theta[:, 1] - theta[:, 2] <= limits.stops.coupled.theta2_minus_theta3_max)
    assert np.all(theta[:, 2] - theta[:, 1] <= limits.stops.coupled.theta3_minus_theta2_max)


@pytest.mark.parametrize("call", [Phantom, config.read, describe, Device])
def test_a_configuration_is_a_name_or_a_path(call):
    with pytest.raises(InvalidInputError, match="expected a"):
        call(123)


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


def test_negative_friction_is_refused_as_an_override_before_any_model():
    """Before, Phantom(describe(overrides={"actuation.friction.viscous": -5e-4})) raised
    Pinocchio's raw "min_dry_friction" traceback and `urdf --set` wrote damping="-1"."""
    with pytest.raises(ParameterFileError,
                       match="after the overrides, .*actuation.yaml: friction.viscous must not be negative"):
        describe(overrides={"actuation.friction.viscous": -5e-4})


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


@pytest.mark.parametrize("name", config.models())
def test_sampled_postures_fill_exactly_the_yamls_limits(name):
    """20000 seeded postures against joint_limits.yaml read here: inside the box, the stops and
    both coupled stops, and reaching each coupled stop to 0.02 rad (so a swapped or tightened
    coupled limit is seen)."""
    data = yaml.safe_load((config.MODELS[name].config / "joint_limits.yaml").read_text())
    joints = ("joint1", "joint2", "joint3")
    lower = np.maximum([data[j]["lower"] for j in joints], [data["stops"][j]["lower"] for j in joints])
    upper = np.minimum([data[j]["upper"] for j in joints], [data["stops"][j]["upper"] for j in joints])
    forward, backward = data["stops"]["theta2_minus_theta3_max"], data["stops"]["theta3_minus_theta2_max"]
    theta = random_states(config.read(name).limits, 20000, seed=5)[0]
    assert (theta >= lower).all() and (theta <= upper).all()
    difference = theta[:, 1] - theta[:, 2]
    assert difference.max() <= forward and -difference.max() >= -forward
    assert (-difference).max() <= backward
    assert difference.max() > forward - 0.02 and (-difference).max() > backward - 0.02


@pytest.mark.parametrize("value, accepted", [(2 * np.pi - 0.1, True), (2 * np.pi + 0.1, False)])
def test_a_joint_limit_is_within_one_turn(value, accepted):
    overrides = {"joint_limits.joint3.upper": value, "joint_limits.stops.joint3.upper": value}
    if accepted:
        assert config.read("premium_1_5", overrides).limits.upper[2] == value
    else:
        with pytest.raises(ParameterFileError, match=r"joint3.upper must be within one turn"):
            config.read("premium_1_5", overrides)


def test_shipped_checks_the_committed_urdf(tmp_path, monkeypatch):
    """shipped() reads the committed files: a committed URDF with a non-physical link is
    refused, naming the file."""
    from phantom_pin.description.build import _shipped, shipped

    model = config.MODELS["premium_1_5"]
    text = model.urdf.read_text()
    bad = tmp_path / "premium_1_5.urdf"
    bad.write_text(text.replace('<mass value="0.0202"/>', '<mass value="-0.0202"/>', 1))
    assert bad.read_text() != text
    monkeypatch.setitem(config.MODELS, "premium_1_5", dataclasses.replace(model, urdf=bad))
    _shipped.cache_clear()
    try:
        with pytest.raises(ParameterFileError, match=str(bad)):
            shipped("premium_1_5")
    finally:
        _shipped.cache_clear()


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
