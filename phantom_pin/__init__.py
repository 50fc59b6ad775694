"""phantom_pin: the PHANToM haptic arms as URDF/MJCF descriptions, Pinocchio models and the
report's equations, from one typed configuration per device (phantom_pin.models())."""

from importlib.metadata import PackageNotFoundError, version

from phantom_pin import drivers
from phantom_pin.config import Config, models
from phantom_pin.description.build import Description, describe
from phantom_pin.device import Device, SimulationResult, simulate
from phantom_pin.dynamics.loader import PhantomLoader, load
from phantom_pin.dynamics.model import Phantom
from phantom_pin.exceptions import (
                                    InvalidInputError,
                                    MissingDataError,
                                    MissingDependencyError,
                                    ParameterFileError,
                                    PhantomPinError,
                                    UnreachableTargetError,
)
from phantom_pin.report import closed_form
from phantom_pin.report.parameters import ReportParameters

try:
    __version__ = version("phantom_pin")
except PackageNotFoundError:  # a source tree on sys.path, not installed
    __version__ = "unknown"

__all__ = ["__version__", "Phantom", "Device", "simulate", "SimulationResult", "load", "PhantomLoader", "Description",
           "describe", "models", "Config", "ReportParameters", "closed_form", "drivers", "PhantomPinError",
           "InvalidInputError", "ParameterFileError", "UnreachableTargetError", "MissingDataError",
           "MissingDependencyError"]
