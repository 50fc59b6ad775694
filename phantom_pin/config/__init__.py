"""Configurations: the named models, their parameter files read once into one typed,
immutable ``Config`` (schema), the links in full (inertial) and the overrides (files)."""

from __future__ import annotations

from pathlib import Path

from phantom_pin.config.files import FILES, apply_overrides, read_documents, read_overrides
from phantom_pin.config.models import DEFAULT, MODELS, Model, models, resolve
from phantom_pin.config.schema import (
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
)
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
    if overrides:
        documents = apply_overrides(documents, overrides)
    return build(documents, name, folder, bool(overrides))
