"""phantom_pin: the PHANToM haptic arms as URDF/MJCF descriptions, Pinocchio models and the
report's equations, from one typed configuration per device (phantom_pin.models())."""

from phantom_pin import drivers
from phantom_pin.config import Config, models
from phantom_pin.description.build import Description, describe
from phantom_pin.device import Device, SimulationResult, simulate
from phantom_pin.dynamics.loader import PhantomLoader, load
from phantom_pin.dynamics.model import Phantom
from phantom_pin.exceptions import (
                                    InvalidInputError,
                                    MissingDataError,
                                    ParameterFileError,
                                    PhantomPinError,
                                    UnreachableTargetError,
)
from phantom_pin.report import closed_form
from phantom_pin.report.parameters import ReportParameters

__all__ = ["Phantom", "Device", "simulate", "SimulationResult", "load", "PhantomLoader", "Description",
           "describe", "models", "Config", "ReportParameters", "closed_form", "drivers", "PhantomPinError",
           "InvalidInputError", "ParameterFileError", "UnreachableTargetError", "MissingDataError"]
