"""phantom_pin: the PHANToM Premium 1.5 as a URDF, a Pinocchio model and the report's equations."""

from phantom_pin import closed_form
from phantom_pin.description import Description, describe
from phantom_pin.device import Device, SimulationResult, simulate
from phantom_pin.exceptions import (InvalidInputError, ParameterFileError, PhantomPinError,
                                    UnreachableTargetError)
from phantom_pin.loader import PhantomLoader, load
from phantom_pin.model import Phantom
from phantom_pin.parameters import Parameters, load_parameters

__all__ = ["Phantom", "Device", "simulate", "SimulationResult", "load", "PhantomLoader", "Description",
           "describe", "Parameters", "load_parameters", "closed_form", "PhantomPinError", "InvalidInputError",
           "ParameterFileError", "UnreachableTargetError"]
