"""The identification's first stage, reading the data: the CSV log, trajectory and rest
postures (io), a driver's rosbag2 recording (bags), the torques' timing against the positions
(timing), and a simulated device logging a trajectory (simulation: a log without a device).
Imports nothing of the later stages (structure, fitting, verdict)."""

from phantom_pin.identification.data.bags import Recording, is_bag, read_bag
from phantom_pin.identification.data.io import (
    TRAJECTORY_COLUMNS,
    Log,
    read_log,
    read_postures,
    read_trajectory,
    write_log,
)
from phantom_pin.identification.data.simulation import track
from phantom_pin.identification.data.timing import TIMINGS, delay_argument

__all__ = ["Log", "read_log", "write_log", "read_trajectory", "read_postures", "TRAJECTORY_COLUMNS", "Recording",
           "read_bag", "is_bag", "TIMINGS", "delay_argument", "track"]
