"""A driver's rosbag2 recording (sqlite3 or mcap, read with ``rosbags``: no ROS install) as a
device log: the JointState topic of a driver profile (phantom_pin.interfaces.profiles), its positions and
efforts in that profile's conventions and units, at the messages' header stamps.

The drivers that publish efforts publish OpenHaptics' joint torques (mN m, on OpenHaptics' joint
angles: the profile's ``effort_unit``); positions are the driver's own angles (its signs, its
elbow relative or absolute: Profile.arm_from_state) and the gimbal's (Profile.gimbal_from_state:
OpenHaptics' raw gimbal angles, the Touch model's). Times are the header stamps (when the driver
read the device), not the recorder's receive times. Messages are put in stamp order; a message
recorded twice (same stamp, same numbers) is dropped; two different messages with one stamp, or
a gap of more than GAP intervals, are refused in one line. Stamps taken from a wall clock jitter:
within io.RATE_TOLERANCE of their mean interval they are used as they are, else the stream is
resampled onto a uniform grid at its mean rate by linear interpolation (``Recording.resampled``).
"""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

import numpy as np

from phantom_pin._validation import uneven
from phantom_pin.exceptions import LogError, MissingDataError
from phantom_pin.identification.data.io import MIN_DURATION, RATE_TOLERANCE, Log
from phantom_pin.interfaces import conventions, profiles

__all__ = ["Recording", "read_bag", "is_bag"]

#: The message type read.
JOINT_STATE = "sensor_msgs/msg/JointState"
#: An interval between stamps longer than this many times the median interval is a gap.
GAP = 3.0
#: Largest swing (rad) of a gimbal angle about its median for the stylus to count as held still:
#: the model carries the stylus locked (config gimbal.locked_at), put at the recording's median;
#: a 0.05 rad swing moves the Touch's 30 g stylus's centre of mass (about 4 cm from the gimbal
#: centre) by 2 mm, 0.6 mN m of its load on joint 1 at most (ESTIMATE: the Touch's gimbal.yaml).
STYLUS_SPREAD = 0.05


@dataclasses.dataclass(frozen=True)
class Recording:
    """What ``read_bag`` read: the ``log`` (report's theta, rad; N m), the ``gimbal`` angles
    (N, 3; OpenHaptics' raw, rad), the ``driver`` profile's name, the ``topic``, the ``messages``
    read, the ``duplicates`` dropped, whether the stamps came ``reordered`` and whether the stream
    was ``resampled`` onto a uniform grid (module doc)."""

    log: Log
    gimbal: np.ndarray
    driver: str
    topic: str
    messages: int
    duplicates: int
    reordered: bool
    resampled: bool

    def lines(self) -> list[str]:
        """One line saying what was read, for the command line."""
        notes = [f"{self.duplicates} message(s) recorded twice dropped" if self.duplicates else "",
                 "stamps out of order, sorted" if self.reordered else "",
                 f"resampled onto a uniform {self.log.rate:.6g} Hz grid (the stamps jitter by more than "
                 f"{100 * RATE_TOLERANCE:g} %)" if self.resampled else ""]
        return [f"{self.topic} ({self.driver}): {self.messages} messages over {self.log.t[-1] - self.log.t[0]:.3f} s "
                f"at {self.log.rate:.6g} Hz (header stamps)" + "".join(f"; {n}" for n in notes if n)]

    def stylus(self) -> np.ndarray:
        """The gimbal angles (rad, (3,)) the stylus was held at: their median over the recording,
        where the stylus is held still (STYLUS_SPREAD) for description.build.held to put the
        model's stylus there; LogError where it swings further (its load then moves with it,
        which a locked stylus does not model)."""
        middle = np.median(self.gimbal, axis=0)
        spread = np.abs(self.gimbal - middle).max(axis=0)
        if (spread > STYLUS_SPREAD).any():
            j = int(np.argmax(spread))
            raise LogError(f"the stylus's gimbal angle {j + 1} swings {spread[j]:.3g} rad about its median in the "
                           f"bag (at most {STYLUS_SPREAD:g} rad): identify with the stylus held still (taped or "
                           "docked), its load is modelled locked", argument="path")
        return middle


def is_bag(path: Path | str) -> bool:
    """Whether ``path`` is a rosbag2 recording: a folder with metadata.yaml, or an .mcap or .db3 file."""
    path = Path(path)
    return (path.is_dir() and (path / "metadata.yaml").is_file()) or path.suffix in (".mcap", ".db3")


def read_bag(path: Path | str, driver: str | None = None, topic: str | None = None) -> Recording:
    """The JointState stream of ``path`` (a rosbag2 folder, or one .mcap/.db3 file of one) as a
    Recording (module doc). ``driver``: the profile (profiles.names()), else recognised from the
    joint names; ``topic``: the JointState topic, else the profile's, or the bag's only one.
    LogError (naming the argument where one is at fault) for a bag that cannot be read as a log;
    MissingDataError where ``rosbags`` is not installed or the driver publishes no efforts."""
    try:
        from rosbags.highlevel import AnyReader, AnyReaderError
        from rosbags.typesys import Stores, get_typestore
    except ImportError:
        raise MissingDataError("reading a bag needs the rosbags package: pip install 'phantom-pin[bags]'",
                               argument="path") from None
    path = Path(path)
    if not path.exists():
        raise LogError(f"{path}: no such bag", argument="path")
    if driver is not None and driver not in profiles.names():
        raise LogError(f"expected one of {', '.join(profiles.names())}, got {driver!r}", argument="driver")
    try:
        with AnyReader([path], default_typestore=get_typestore(Stores.ROS2_HUMBLE)) as reader:
            connection = _connection(reader.connections, path, topic, driver)
            raw = [(reader.deserialize(data, connection.msgtype))
                   for connection, _, data in reader.messages(connections=[connection])]
    except LogError:
        raise
    except (AnyReaderError, OSError, ValueError, KeyError) as error:
        raise LogError(f"{path}: not a readable rosbag2 recording ({error})", argument="path") from None
    profile = _profile(raw, connection.topic, driver)
    return _recording(raw, profile, connection.topic)


def _connection(connections: list, path: Path, topic: str | None, driver: str | None) -> Any:
    """The JointState connection to read (read_bag's ``topic`` and ``driver``)."""
    streams = [c for c in connections if c.msgtype == JOINT_STATE]
    if topic is not None:
        return _named(connections, streams, path, topic)
    if driver is not None:
        chosen = [c for c in streams if c.topic == profiles.load(driver).joint_states.topic]
        if chosen:
            return chosen[0]
    topics = {c.topic for c in streams}
    if len(topics) != 1:
        raise LogError(f"{path} holds {len(topics)} {JOINT_STATE} topics"
                       + (f" ({', '.join(sorted(topics))}): choose one with --topic"
                          if streams else ""), argument="topic")
    return streams[0]


def _named(connections: list, streams: list, path: Path, topic: str) -> Any:
    """The connection of ``topic``, one of the JointState ``streams``; LogError naming them otherwise."""
    chosen = [c for c in connections if c.topic == topic]
    if not chosen or chosen[0].msgtype != JOINT_STATE:
        raise LogError(f"{topic} is not a {JOINT_STATE} topic of {path} (those: "
                       f"{', '.join(sorted({c.topic for c in streams})) or 'none'})", argument="topic")
    return chosen[0]


def _profile(messages: list, topic: str, driver: str | None) -> profiles.Profile:
    """The driver profile of the messages: ``driver``'s, or the one whose six joint names they
    carry (and, where several drivers share them, whose topic they came on)."""
    if not messages:
        raise LogError(f"{topic}: no messages", argument="topic")
    names = tuple(messages[0].name)
    if driver is not None:
        profile = profiles.load(driver)
        if not set(profile.joint_states.names) <= set(names):
            raise LogError(f"{topic} names its joints {', '.join(names)}, not {driver}'s "
                           f"({', '.join(profile.joint_states.names)})", argument="driver")
        return profile
    matching = [name for name in profiles.names() if set(profiles.load(name).joint_states.names) <= set(names)]
    if len(matching) > 1:            # drivers that share joint names: the topic tells them apart
        matching = [name for name in matching if profiles.load(name).joint_states.topic == topic] or matching
    if len(matching) != 1:
        raise LogError(f"{topic}: joints {', '.join(names)} are "
                       + (f"those of {', '.join(matching)}" if matching else "no driver profile's") +
                       ": name the driver (--driver, one of " + ", ".join(profiles.names()) + ")", argument="driver")
    return profiles.load(matching[0])


def _recording(messages: list, profile: profiles.Profile, topic: str) -> Recording:
    """The messages of ``profile``'s JointState as a Recording (module doc)."""
    if profile.joint_states.effort_unit is None:
        raise MissingDataError(f"{profile.name} publishes no efforts on {topic} (its effort[] is empty): its bags "
                               "hold no torques to identify from", argument="driver")
    stamps, positions, efforts = [], [], []
    for message in messages:
        index = [list(message.name).index(name) for name in profile.joint_states.names]
        if len(message.position) < 6 or len(message.effort) < 6:
            raise LogError(f"{topic}: a message stamped {_stamp(message)} ns carries {len(message.position)} positions "
                           f"and {len(message.effort)} efforts for its six joints", argument="path")
        stamps.append(_stamp(message))
        positions.append(np.asarray(message.position, dtype=float)[index])
        efforts.append(np.asarray(message.effort, dtype=float)[index])
    ns, q, e = np.array(stamps, dtype=np.int64), np.array(positions), np.array(efforts)
    order = np.argsort(ns, kind="stable")
    t = (ns - ns.min()) / 1e9           # s from the first stamp (divided: 1e-9 is inexact, 1e9 is not)
    reordered = bool((order != np.arange(len(t))).any())
    t, q, e = t[order], q[order], e[order]
    same = np.flatnonzero(np.diff(t) == 0)
    if not (np.array_equal(q[same], q[same + 1]) and np.array_equal(e[same], e[same + 1])):
        k = same[np.flatnonzero((q[same] != q[same + 1]).any(axis=1) | (e[same] != e[same + 1]).any(axis=1))[0]]
        raise LogError(f"{topic}: two different messages stamped {t[k]:.9f} s after the first: the stamps do not "
                       "identify the samples", argument="path")
    keep = np.concatenate([[True], np.diff(t) > 0])
    t, q, e = t[keep], q[keep], e[keep]
    t, q, e, resampled = _uniform(t, q, e, topic)
    theta = np.array([profile.arm_from_state(row) for row in q[:, :3].tolist()])
    tau = conventions.tau_from_openhaptics_torque(e[:, :3])             # mN m on OpenHaptics' angles
    gimbal = np.array([profile.gimbal_from_state(row) for row in q[:, 3:].tolist()])
    return Recording(Log(t, theta, tau), gimbal, profile.name, topic, len(messages), int((~keep).sum()),
                     reordered, resampled)


def _stamp(message: object) -> int:
    """A message's header stamp (ns: an epoch's seconds in a double keep only 0.2 us)."""
    stamp = message.header.stamp          # type: ignore[attr-defined]
    return int(stamp.sec) * 10**9 + int(stamp.nanosec)


def _uniform(t: np.ndarray, q: np.ndarray, e: np.ndarray,
             topic: str) -> tuple[np.ndarray, np.ndarray, np.ndarray, bool]:
    """The stream on a uniform grid (module doc): as it is where its intervals are within
    RATE_TOLERANCE of their mean, else interpolated at its mean rate; LogError for a gap."""
    if len(t) < 2 or t[-1] - t[0] < MIN_DURATION:
        raise LogError(f"{topic}: too short ({t[-1] - t[0] if len(t) else 0:.3g} s of stamps; at least "
                       f"{MIN_DURATION} s)", argument="path")
    step = np.diff(t)
    median = float(np.median(step))
    if step.max() > GAP * median:
        k = int(np.argmax(step))
        raise LogError(f"{topic}: a gap of {1e3 * step[k]:.3g} ms after {t[k] - t[0]:.3f} s in a stream at "
                       f"{1 / median:.4g} Hz (messages lost): record again, or cut the bag before or after it",
                       argument="path")
    if not uneven(step, RATE_TOLERANCE):
        return t, q, e, False
    grid = np.linspace(t[0], t[-1], len(t))
    q, e = (np.column_stack([np.interp(grid, t, x[:, j]) for j in range(6)]) for x in (q, e))
    return grid, q, e, True
