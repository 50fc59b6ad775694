"""Identification of a PHANToM's own dynamics (docs/identification.md), in four stages, each a
subpackage that imports only the ones before it: ``data`` (the CSV log and trajectory, a
driver's rosbag2 recording, the torques' timing, a simulated device's log), ``structure`` (the
regressor, base parameters, the structures a fit takes, the prior), ``fitting`` (filtering,
least squares, the choices from the log, the refusals, the estimate, gravity from rest, the
excitation) and ``verdict`` (identify and its report, the overlay, the HTML page).

The public names: ``identify`` (a log and a Phantom -> Identification: report, warnings, write
as a --params overlay; RefusedError for a log whose fit should not be written), ``estimate`` (a
log and a Phantom -> Fit, in the ``general`` structure or the ``report``'s), ``optimise`` (an
excitation trajectory), ``read_log``/``write_log``/
``read_trajectory`` and ``Log``, ``overlay`` (a Fit as --params keys),
``track`` (a simulated device logging a trajectory), ``Regressor`` and ``base_parameters``;
``LogError`` for a bad log. What the command line also takes: ``read_bag``/``is_bag`` and
``Recording`` (a driver's bag), ``read_postures``, ``rest_of``/``Rest``/``estimate_gravity``
and ``gravity_overlay`` (gravity from rest), ``stylus_keys`` (a held stylus's posture),
``report_page`` (identify --report), ``refusal``, ``delay_argument``, ``continuous_effort``,
``TRAJECTORY_COLUMNS``, ``MIN_SPEEDS`` and ``Excitation``."""

from phantom_pin.exceptions import LogError
from phantom_pin.identification.data import (
    TRAJECTORY_COLUMNS,
    Log,
    Recording,
    delay_argument,
    is_bag,
    read_bag,
    read_log,
    read_postures,
    read_trajectory,
    track,
    write_log,
)
from phantom_pin.identification.fitting import (
    MIN_SPEEDS,
    Excitation,
    Fit,
    RefusedError,
    Rest,
    continuous_effort,
    estimate,
    estimate_gravity,
    optimise,
    refusal,
    rest_of,
)
from phantom_pin.identification.structure import Regressor, base_parameters
from phantom_pin.identification.verdict import (
    Identification,
    gravity_overlay,
    identify,
    overlay,
    report_page,
    stylus_keys,
)

__all__ = ["identify", "Identification", "RefusedError", "estimate", "Fit", "optimise", "Excitation", "read_log",
           "write_log", "read_trajectory", "Log",
           "LogError", "overlay", "track", "Regressor", "base_parameters",
           "read_bag", "is_bag", "Recording", "read_postures", "rest_of", "Rest", "estimate_gravity",
           "gravity_overlay", "stylus_keys", "report_page", "refusal", "delay_argument", "continuous_effort",
           "TRAJECTORY_COLUMNS", "MIN_SPEEDS"]
