"""The named configurations: a model is a few declared attributes (robot_descriptions.py's
style), and ``resolve`` turns a name or a folder into one."""

from __future__ import annotations

import dataclasses
import os
from pathlib import Path

from phantom_pin._paths import DESCRIPTION_DIR
from phantom_pin.exceptions import InvalidInputError


@dataclasses.dataclass(frozen=True)
class Model:
    """A configuration of the description package: its ``name``, a one-line ``title``, its
    ``config`` folder (config/NAME), the top-level xacros that generate its URDF and SRDF (one
    pair for every model, given ``model:=NAME``: ``xacro_args``), and the committed generated
    files (URDF, SRDF, MJCF and its scene ``mjcf/scene_ROBOT.xml``, and ``links_file``: the
    links in full, the xacro's input, generated from physical_parameters.yaml)."""

    name: str
    title: str
    urdf_xacro: Path
    srdf_xacro: Path
    urdf: Path
    srdf: Path
    mjcf: Path
    scene: Path
    links_file: Path

    @property
    def config(self) -> Path:
        return DESCRIPTION_DIR / "config" / self.name

    @property
    def xacro_mappings(self) -> dict[str, str]:
        """The xacro arguments that select this model, as xacro.process_file's ``mappings``
        (and robot_descriptions.py's XACRO_ARGS): {"model": NAME}."""
        return {"model": self.name}

    @property
    def xacro_args(self) -> tuple[str, ...]:
        """The command-line arguments of ``xacro`` that select this model in ``urdf_xacro`` and
        ``srdf_xacro`` (the other arguments keep their defaults: the model's own files)."""
        return tuple(f"{arg}:={value}" for arg, value in self.xacro_mappings.items())


def _model(name: str, title: str) -> Model:
    """The model ``name``: its robot and every file of it are named ``name`` (urdf/NAME.urdf, ...)."""
    d = DESCRIPTION_DIR
    return Model(name, title, d / "urdf" / "phantom.urdf.xacro", d / "srdf" / "phantom.srdf.xacro",
                 d / "urdf" / f"{name}.urdf", d / "srdf" / f"{name}.srdf", d / "mjcf" / f"{name}.xml",
                 d / "mjcf" / f"scene_{name}.xml", d / "config" / name / "links.yaml")


#: The shipped configurations, by name; the first is the default everywhere.
MODELS = {model.name: model for model in (
    _model("premium_1_5", "PHANToM Premium 1.5, the report's numbers"),
    _model("premium_1_5_cad", "PHANToM Premium 1.5, mahilab/Phantom's CAD mass properties and lengths"),
    _model("touch", "Geomagic Touch / PHANToM Omni: the report's arm at its size, ESTIMATED inertias, "
                    "no public motor data"),
)}
DEFAULT = "premium_1_5"
#: The robot names of 0.x before each model's files and robot took its name (CHANGELOG.md):
#: refused for one release, naming the model.
RENAMED = {"phantom_1_5": "premium_1_5", "phantom_1_5_cad": "premium_1_5_cad", "phantom_touch": "touch"}


def models() -> list[str]:
    """The names of the shipped configurations (phantom_pin.describe(name) and --model NAME)."""
    return list(MODELS)


def renamed(name: object, argument: str = "model") -> None:
    """InvalidInputError naming ``argument`` if ``name`` is an old name of a model (RENAMED)."""
    if isinstance(name, str) and name in RENAMED:
        new = RENAMED[name]
        raise InvalidInputError(f"{name!r} is the old name of the model {new!r} (its files are {new}.urdf, "
                                f"{new}.srdf, {new}.xml now): use {new!r}", argument=argument)


def resolve(model: object, argument: str = "model") -> tuple[str, Path, Model | None]:
    """(name, config folder, Model or None) of a model name or a configuration folder.

    A string without a path separator that names no folder must be a model's name;
    InvalidInputError naming ``argument`` otherwise."""
    if not isinstance(model, (str, os.PathLike)):
        raise InvalidInputError(f"expected a model name ({', '.join(MODELS)}) or a "
                                f"configuration folder, got {model!r}", argument=argument)
    if isinstance(model, str) and model in MODELS:
        named = MODELS[model]
        return named.name, named.config, named
    renamed(model, argument)
    folder = Path(model)
    if not folder.is_dir():
        if isinstance(model, str) and os.sep not in model and "/" not in model:
            raise InvalidInputError(f"{model!r} is neither a model ({', '.join(MODELS)}) nor a folder",
                                    argument=argument)
        raise InvalidInputError(f"{folder} is not a folder", argument=argument)
    shipped = next((m for m in MODELS.values() if m.config.resolve() == folder.resolve()), None)
    return (shipped.name if shipped else str(folder)), folder, shipped
