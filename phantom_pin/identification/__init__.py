"""Identification of a PHANToM's own dynamics: regressor, base parameters, excitation,
estimation, physical consistency, and the CSV log (docs/identification.md).

The public names: ``identify`` (a log and a Phantom -> Identification: report, warnings, write
as a --params overlay; RefusedError for a log whose fit should not be written), ``estimate`` (a
log and a Phantom -> Fit, in the ``general`` structure or the ``report``'s), ``optimise`` (an
excitation trajectory), ``read_log``/``write_log``/
``read_trajectory`` and ``Log``, ``overlay`` (a Fit as --params keys),
``track`` (a simulated device logging a trajectory), ``Regressor`` and ``base_parameters``;
``LogError`` for a bad log."""

from phantom_pin.exceptions import LogError
from phantom_pin.identification.base import base_parameters
from phantom_pin.identification.estimation import Fit, estimate
from phantom_pin.identification.excitation import Excitation, optimise
from phantom_pin.identification.io import Log, read_log, read_trajectory, write_log
from phantom_pin.identification.overlays import overlay
from phantom_pin.identification.regressor import Regressor
from phantom_pin.identification.result import Identification, RefusedError, identify
from phantom_pin.identification.simulation import track

__all__ = ["identify", "Identification", "RefusedError", "estimate", "Fit", "optimise", "Excitation", "read_log",
           "write_log", "read_trajectory", "Log",
           "LogError", "overlay", "track", "Regressor", "base_parameters"]
