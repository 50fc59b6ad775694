"""phantom_pin: the PHANToM haptic arms as URDF/MJCF descriptions, Pinocchio models and the
report's equations, from one typed configuration per device (phantom_pin.models()).

One way to make each object: ``Phantom(description)`` (``Phantom()`` the default model;
``Phantom.from_model(model)``, ``Phantom.from_folder(path)``), ``Device(phantom)``
(``Device.from_model(model)``), ``load(description)`` (``load_files(loader)`` for a PhantomLoader's
files), each Description from ``describe(name or folder, overrides=...)``. A Phantom is passed as
``phantom`` and a Device as ``device`` wherever a function takes one (``check(phantom)``,
``simulate(..., device=)``, ``identification.optimise(phantom)``)."""

from importlib.metadata import PackageNotFoundError, version

from phantom_pin import _moved
from phantom_pin.config import Config, models
from phantom_pin.description.build import Description, describe
from phantom_pin.device import Device, Feel, SimulationResult, feel, simulate
from phantom_pin.device.mujoco_plant import simulate_mujoco
from phantom_pin.dynamics.loader import PhantomLoader, load, load_files
from phantom_pin.dynamics.phantom import Phantom
from phantom_pin.dynamics.verification import check
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

_moved.install()    # the old paths of moved modules, for one release (CHANGELOG.md)


def __getattr__(name: str):  # noqa: ANN202 - a module's __getattr__
    """``phantom_pin.X`` for a module X that moved (phantom_pin._moved: a DeprecationWarning)."""
    return _moved.root_attribute(name)


try:
    __version__ = version("phantom_pin")
except PackageNotFoundError:  # a source tree on sys.path, not installed
    __version__ = "unknown"

__all__ = ["__version__", "Phantom", "Device", "simulate", "feel", "Feel", "simulate_mujoco", "SimulationResult",
           "load", "load_files", "PhantomLoader", "Description", "describe", "check", "models", "Config",
           "ReportParameters", "closed_form",
           "PhantomPinError", "InvalidInputError", "ParameterFileError", "UnreachableTargetError",
           "MissingDataError", "MissingDependencyError"]
