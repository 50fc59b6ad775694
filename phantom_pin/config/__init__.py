"""Configurations: the named models, their parameter files read once into one typed,
immutable ``Config`` (types, read by reader, built by builders), the links and bodies (bodies,
inertial) and the overrides (files)."""

from __future__ import annotations

from pathlib import Path

from phantom_pin.config.builders import REPORT_SEGMENTS, build, in_full
from phantom_pin.config.files import FILES, MODEL_KEY, apply_overrides, read_documents, read_overrides
from phantom_pin.config.models import DEFAULT, MODELS, Model, models, resolve
from phantom_pin.config.types import (
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
)
from phantom_pin.exceptions import ParameterFileError
from phantom_pin.inertial import Inertial

__all__ = ["read", "MODEL_KEY", "Config", "Inertial", "models", "Model", "MODELS", "DEFAULT", "FILES", "read_overrides",
           "Actuation", "CoupledStops", "Encoder", "Friction", "Kinematics", "Limits", "Motor",
           "MujocoSettings", "Scene", "Stops"]


def read(source: str | Path = DEFAULT, overrides: dict[str, object] | None = None) -> Config:
    """The Config of a model name (phantom_pin.models()) or a configuration folder, its
    files read once each, with ``overrides`` (dotted keys, files.apply_overrides) applied.
    An override ``model`` (files.MODEL_KEY, as identify's overlay writes it) must name this
    model. Raises ParameterFileError naming the file and the key (or ``model`` for overrides
    made for another model), InvalidInputError naming ``model`` for an unknown name or folder."""
    name, folder, _ = resolve(source)
    overrides = dict(overrides or {})
    made_for = overrides.pop(MODEL_KEY, None)
    if made_for is not None and made_for != name:
        raise ParameterFileError(f"{MODEL_KEY}: these overrides were made for the model {made_for!r} (an "
                                 f"identification's overlay, valid on its lengths and links only), not for "
                                 f"{name!r}; choose --model {made_for}")
    documents = read_documents(folder)
    in_links = {key: value for key, value in overrides.items() if section(key) == "links"}
    if in_links and "links" not in documents["physical_parameters_file"]:
        # a model in the report's form given links in full (identify's overlay): its five
        # bodies in full, as its files give them (builders.in_full), then every override on them
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
