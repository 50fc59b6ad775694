"""One way to make each object and one name for each role (issue 40, step 2): every public
function or method that takes a Phantom calls it ``phantom``, a Device ``device``, a Description
``description``; the entry points without a top-level name have one; and a function given the
wrong object refuses it naming the argument and the call that makes the right one; no function
below the entry points defaults to a configuration."""

import importlib
import inspect
import pkgutil
import re
from pathlib import Path

import pytest

import phantom_pin
from phantom_pin import InvalidInputError, Phantom, config

#: The object each role's parameter holds (its annotation names the class), and that name.
ROLES = {"Phantom": "phantom", "Device": "device", "Description": "description"}


def _public_callables():
    """(qualified name, function) of every name in every module's __all__: functions, and the
    methods and classmethods of classes (their own, not inherited), private ones left out."""
    modules = ["phantom_pin"] + [m.name for m in pkgutil.walk_packages(phantom_pin.__path__, "phantom_pin.")]
    for module_name in modules:
        try:
            module = importlib.import_module(module_name)
        except ImportError:  # an optional dependency (ROS 2): its signatures are read where it imports
            continue
        for name in getattr(module, "__all__", ()):
            item = getattr(module, name)
            if inspect.isfunction(item):
                yield f"{module_name}.{name}", item
            elif inspect.isclass(item):
                for attribute, member in vars(item).items():
                    function = member.__func__ if isinstance(member, (classmethod, staticmethod)) else member
                    if inspect.isfunction(function) and (attribute == "__init__" or not attribute.startswith("_")):
                        yield f"{module_name}.{name}.{attribute}", function


def test_every_parameter_holding_a_phantom_device_or_description_has_its_role_name():
    """A parameter annotated with exactly one of the roles' classes (alone or with None) is named
    for that role: no ``model``, ``source`` or ``robot`` holding a Phantom any more."""
    wrong, seen = [], 0
    for qualified, function in _public_callables():
        for parameter in inspect.signature(function).parameters.values():
            annotation = parameter.annotation
            if not isinstance(annotation, str):
                annotation = getattr(annotation, "__name__", str(annotation))
            kinds = [cls for cls in ROLES if re.search(rf"\b{cls}\b", annotation)]
            other = re.sub(r"\b(None|type\[[^]]*\])\b", "", annotation)
            if len(kinds) == 1 and re.fullmatch(rf"\s*(\|\s*)*{kinds[0]}(\s*\|\s*)*", other):
                seen += 1
                if parameter.name != ROLES[kinds[0]]:
                    wrong.append(f"{qualified}({parameter.name}: {annotation})")
    assert seen >= 15 and not wrong


def test_the_entry_points_have_top_level_names():
    from phantom_pin.device.mujoco_plant import simulate_mujoco
    from phantom_pin.dynamics.loader import load_files
    from phantom_pin.dynamics.verification import check

    assert (phantom_pin.check, phantom_pin.simulate_mujoco, phantom_pin.load_files) == (check, simulate_mujoco,
                                                                                         load_files)
    assert {"check", "simulate_mujoco", "load_files"} <= set(phantom_pin.__all__)


def test_optimise_names_its_phantom():
    from phantom_pin.identification import optimise

    assert list(inspect.signature(optimise).parameters)[0] == "phantom"
    with pytest.raises(InvalidInputError) as error:
        optimise("touch", iterations=1, restarts=1)
    assert error.value.argument == "phantom"


def test_a_device_of_a_named_model_is_that_models_phantom():
    """Device.from_model(name) wraps Phantom.from_model(name): the same gravity (exactly) and
    configuration."""
    theta = [0.1, 0.4, 0.9]
    for name in phantom_pin.models():
        device, phantom = phantom_pin.Device.from_model(name), Phantom.from_model(name)
        assert device.config is phantom.config
        assert (device.phantom.gravity(theta) == phantom.gravity(theta)).all()


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
