"""Configurations: the named models, their parameter files read once into one typed,
immutable ``Config`` (types, read by reader, built by builders, ``read`` in load), the links and
bodies (inertial) and the overrides (files). This module only hands their names on."""

from __future__ import annotations

from phantom_pin.config.builders import REPORT_SEGMENTS
from phantom_pin.config.files import FILES, MODEL_KEY, read_overrides
from phantom_pin.config.load import read, section
from phantom_pin.config.models import DEFAULT, MODELS, RENAMED, Model, models, renamed, resolve
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
from phantom_pin.description.inertial import Inertial

__all__ = ["read", "MODEL_KEY", "Config", "Inertial", "models", "Model", "MODELS", "DEFAULT", "FILES", "read_overrides",
           "Actuation", "CoupledStops", "Encoder", "Friction", "Kinematics", "Limits", "Motor",
           "MujocoSettings", "Scene", "Stops", "REPORT_SEGMENTS", "section", "resolve", "RENAMED", "renamed"]
