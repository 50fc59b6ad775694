"""phantom_pin.config.models: one name per shipped model. Its robot and every committed file
take it (urdf/NAME.urdf, srdf/NAME.srdf, mjcf/NAME.xml, mjcf/scene_NAME.xml,
include/NAME.h), and the robot names of 0.x are refused with the new name in the API, on
the command line and in plain xacro."""

import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

import phantom_pin
from helpers import run_cli
from phantom_pin import Device, InvalidInputError, Phantom, config, describe
from phantom_pin.config import MODELS, RENAMED
from phantom_pin.description.build import shipped

#: The robot names before the files followed the models (CHANGELOG.md, written here by hand).
OLD = {"phantom_1_5": "premium_1_5", "phantom_1_5_cad": "premium_1_5_cad", "phantom_touch": "touch"}


@pytest.mark.parametrize("name", sorted(MODELS))
def test_a_models_robot_and_files_carry_its_name(name):
    model = MODELS[name]
    folder = model.urdf.parent.parent
    assert [model.urdf, model.srdf, model.mjcf, model.scene] == [
        folder / "urdf" / f"{name}.urdf", folder / "srdf" / f"{name}.srdf", folder / "mjcf" / f"{name}.xml",
        folder / "mjcf" / f"scene_{name}.xml"]
    assert ET.parse(model.urdf).getroot().get("name") == ET.parse(model.srdf).getroot().get("name") == name
    assert ET.parse(model.mjcf).getroot().get("model") == name
    assert (folder / "include" / f"{name}.h").is_file()
    generated = {p.stem.removeprefix("scene_").removesuffix("_driver") for d in ("urdf", "srdf", "mjcf", "include")
                 for p in (folder / d).iterdir() if p.suffix in (".urdf", ".srdf", ".xml", ".h")}
    assert generated == set(MODELS)


@pytest.mark.parametrize("old", sorted(OLD))
def test_an_old_name_is_refused_with_the_new_one(old, tmp_path):
    new = OLD[old]
    assert RENAMED == OLD
    for call in (lambda: describe(old), lambda: shipped(old)):
        with pytest.raises(InvalidInputError, match=f"'{old}' is the old name of the model '{new}'") as error:
            call()
        assert error.value.argument == "model"
    code, out, err = run_cli("--model", old, "urdf", "-o", tmp_path / "a.urdf")
    assert (code, out) == (2, "") and err.count("\n") == 1 and f"use '{new}'" in err
    assert not (tmp_path / "a.urdf").exists()
    xacro = Path(sys.executable).with_name("xacro")
    result = subprocess.run([str(xacro), str(MODELS[new].urdf_xacro), f"model:={old}"], capture_output=True,
                            text=True, timeout=60)
    assert result.returncode != 0 and f"{old} is now called {new} (model:={new})" in result.stderr


def test_models_are_named_and_resolve_like_folders():
    assert config.models() == phantom_pin.models() == ["premium_1_5", "premium_1_5_cad", "touch"]
    by_name, by_folder = config.read("premium_1_5"), config.read(MODELS["premium_1_5"].config)
    assert by_name == by_folder and by_name.name == "premium_1_5"
    for call in (config.read, describe, Phantom, Device, phantom_pin.load):
        with pytest.raises(InvalidInputError, match="premium_9"):
            call("premium_9")
    with pytest.raises(InvalidInputError, match="expected a model name"):
        config.read(123)


@pytest.mark.parametrize("call", [Phantom, config.read, describe, Device])
def test_a_configuration_is_a_name_or_a_path(call):
    with pytest.raises(InvalidInputError, match="expected a"):
        call(123)
