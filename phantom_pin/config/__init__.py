"""Configurations: the named models, their parameter files read once into one typed,
immutable ``Config`` (schema), the links in full (inertial) and the overrides (files)."""

from __future__ import annotations

from pathlib import Path

from phantom_pin.config.files import FILES, apply_overrides, read_documents, read_overrides
from phantom_pin.config.models import DEFAULT, MODELS, Model, models, resolve
from phantom_pin.config.schema import (
    REPORT_SEGMENTS,
    Actuation,
    Config,
    CoupledStops,
    Encoder,
    Friction,
    Kinematics,
    Limits,
    Motor,
    MujocoSettings,
    Scene,
    Stops,
    build,
    in_full,
)
from phantom_pin.exceptions import ParameterFileError
from phantom_pin.inertial import Inertial

__all__ = ["read", "Config", "Inertial", "models", "Model", "MODELS", "DEFAULT", "FILES", "read_overrides",
           "Actuation", "CoupledStops", "Encoder", "Friction", "Kinematics", "Limits", "Motor",
           "MujocoSettings", "Scene", "Stops"]


def read(source: str | Path = DEFAULT, overrides: dict[str, object] | None = None) -> Config:
    """The Config of a model name (phantom_pin.models()) or a configuration folder, its
    files read once each, with ``overrides`` (dotted keys, files.apply_overrides) applied.
    Raises ParameterFileError naming the file and the key, InvalidInputError naming
    ``model`` for an unknown name or folder."""
    name, folder, _ = resolve(source)
    documents = read_documents(folder)
    overrides = dict(overrides or {})
    in_links = {key: value for key, value in overrides.items() if section(key) == "links"}
    if in_links and "links" not in documents["physical_parameters_file"]:
        # a model in the report's form given links in full (identify's overlay): its five
        # bodies in full, as its files give them (schema.in_full), then every override on them
        mixed = sorted(key for key in overrides if section(key) in REPORT_SEGMENTS)
        if mixed:
            raise ParameterFileError(f"{mixed[0]}: the report's segments and links.* describe the same bodies "
                                     "two ways; give the links in full only")
        documents = in_full(documents, build(documents, name, folder, False))
    if overrides:
        documents = apply_overrides(documents, overrides)
    return build(documents, name, folder, bool(overrides))


def section(key: object) -> str:
    """The top-level section of physical_parameters.yaml an override key names ("links" for
    "links.forearm_link.mass" and "physical_parameters.links.forearm_link.mass")."""
    parts = str(key).split(".")
    return parts[1] if parts[0] == "physical_parameters" and len(parts) > 1 else parts[0]
