"""What crosses between the libHD stand-in (C) and its device (plant.py), and the device's record.

The stand-in's layout.h is written from these constants (stand_in.layout): one source for both
sides. plant.py's doc says what each exchange means.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from phantom_pin.exceptions import InvalidInputError

#: The figures of the ``ready`` line, in order (numbers, then the model type, the rest of the line).
INFO_FIELDS = ("max_force", "max_continuous_force", "max_stiffness", "peak_torque1", "peak_torque2",
               "peak_torque3", "has_gimbal", "workspace_min_x", "workspace_min_y", "workspace_min_z",
               "workspace_max_x", "workspace_max_y", "workspace_max_z")
#: A command's doubles by offset: the flag (QUIT, DISABLED: HD_FORCE_OUTPUT off, or ENABLED), the
#: force (N, OpenHaptics' axes), the joint torques (mN m on OpenHaptics' angles), the period (s)
#: they are held over, the hand's force (N, OpenHaptics' axes, at the gimbal centre), and 1 where
#: a frame ended in the tick (0: no callback ran a frame, and the command is zero).
COMMAND_LAYOUT = {"FLAG": 0, "FORCE": 1, "TORQUE": 4, "PERIOD": 7, "HAND": 8, "FRAMED": 11}
COMMAND = 12
QUIT, DISABLED, ENABLED = -1, 0, 1
#: A state's doubles by offset: joint angles (rad), gimbal angles (rad), position (mm), velocity
#: (mm/s), the column-major transform (mm), then 0 or, where the plant failed, 1.
STATE_LAYOUT = {"JOINT": 0, "GIMBAL": 3, "POSITION": 6, "VELOCITY": 9, "TRANSFORM": 12}
STATE = 29
#: The record's columns (one row per tick): the tick, its time (s), whether force output was
#: on, whether a frame ended in it, the force (N) and joint torques (mN m) sent and the hand's
#: force (N), the report's theta (rad) and dtheta (rad/s) served in that tick, OpenHaptics'
#: joint and gimbal angles served (rad), the torque the command and the hand put on theta (N m,
#: before the motors' saturation) and the torque applied after it (N m).
RECORD_COLUMNS = ("tick", "t", "enabled", "framed", "force1", "force2", "force3", "torque1", "torque2", "torque3",
                  "hand1", "hand2", "hand3",
                  "theta1", "theta2", "theta3", "dtheta1", "dtheta2", "dtheta3", "angle1", "angle2", "angle3",
                  "gimbal1", "gimbal2", "gimbal3", "tau1", "tau2", "tau3", "applied1", "applied2", "applied3")


#: The record's first line (then float64 rows of RECORD_COLUMNS, native byte order).
RECORD_HEADER = "phantom_pin stand-in record: " + ",".join(RECORD_COLUMNS) + "\n"


def read_record(path: str | Path) -> dict[str, np.ndarray]:
    """The stand-in's record (PHANTOM_PIN_HD_RECORD): RECORD_COLUMNS -> (ticks,) arrays."""
    try:
        data = Path(path).read_bytes()
    except OSError as error:
        raise InvalidInputError(f"cannot read it: {error.strerror}", argument="path") from None
    header = RECORD_HEADER.encode()
    if not data.startswith(header) or (len(data) - len(header)) % (8 * len(RECORD_COLUMNS)):
        raise InvalidInputError("not a stand-in record of this version", argument="path")
    table = np.frombuffer(data[len(header):], dtype=np.float64).reshape(-1, len(RECORD_COLUMNS))
    return {name: table[:, i].copy() for i, name in enumerate(RECORD_COLUMNS)}
