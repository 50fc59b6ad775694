"""Typed, checked reading of a configuration's parameter documents: every number finite and
within its scale, every vector of its length, every error naming the file and the key."""

from __future__ import annotations

import math
from pathlib import Path
from typing import cast

from phantom_pin.config.files import FILES, is_number
from phantom_pin.exceptions import ParameterFileError

#: Largest |joint limit| (rad): a revolute joint's range beyond one turn each way repeats
#: postures and describes no stop of this arm (mahilab's widest stop is 3.74 rad).
JOINT_LIMIT_BOUND = 2 * math.pi
#: Largest magnitude of any number of a configuration (SI units): the largest shipped is 1750
#: (kg/m^3); past it squares and products of inertia overflow (l1 = 1e308: OverflowError) and
#: MuJoCo's first step goes NaN. A scale, not a physical limit: a desk-top arm is far inside it.
MAX_MAGNITUDE = 1e6
#: The MJCF's timestep (s): a haptic loop's 1e-6 to 1e-2 s (MuJoCo went NaN on its first step
#: of 1 s with the shipped stops and friction solref).
TIMESTEP_RANGE = (1e-6, 1e-2)


class Reader:
    """Typed, checked access to the documents; every error names the file and the key."""

    def __init__(self, documents: dict[str, dict], folder: Path, overridden: bool) -> None:
        self.documents, self.folder, self.overridden = documents, folder, overridden

    def error(self, arg: str, message: str) -> ParameterFileError:
        prefix = "after the overrides, " if self.overridden else ""
        return ParameterFileError(f"{prefix}{self.folder / FILES[arg]}: {message}")

    def node(self, arg: str, *keys: str) -> object:
        node: object = self.documents[arg]
        for depth, key in enumerate(keys):
            if not isinstance(node, dict) or key not in node:
                raise self.error(arg, f"missing key {'.'.join(keys[:depth + 1])}")
            node = node[key]
        return node

    def number(self, arg: str, *keys: str, positive: bool = False, non_negative: bool = False) -> float:
        node = self.node(arg, *keys)
        name = ".".join(keys)
        if not is_number(node):
            raise self.error(arg, f"{name} must be a finite number, got {node!r}")
        value = cast(float, node)  # an int or a float (is_number)
        if not math.isfinite(value):
            raise self.error(arg, f"{name} must be a finite number, got {value!r}")
        if abs(value) > MAX_MAGNITUDE:
            raise self.error(arg, f"{name} must be at most {MAX_MAGNITUDE:g} in magnitude (SI units), got {value!r}")
        if positive and value <= 0:
            raise self.error(arg, f"{name} must be positive, got {value!r}")
        if non_negative and value < 0:
            raise self.error(arg, f"{name} must not be negative, got {value!r}")
        return value

    def per_joint(self, arg: str, *keys: str, joints: tuple[str, ...], non_negative: bool = False) -> tuple:
        """A per-joint number (files.PER_JOINT): one number, the same on every joint, or a mapping
        with exactly ``joints`` as keys, each a number checked as ``number`` does; the values
        in the order of ``joints``, each keeping its type."""
        node = self.node(arg, *keys)
        name = ".".join(keys)
        if is_number(node):
            value = self.number(arg, *keys, non_negative=non_negative)
            return tuple(value for _ in joints)
        if not isinstance(node, dict):
            raise self.error(arg, f"{name} must be a finite number (the same on every joint) or a mapping "
                                  f"{{{', '.join(joints)}}} of them, got {node!r}")
        extra = [str(key) for key in node if key not in joints]
        if extra:
            raise self.error(arg, f"{name}.{extra[0]} is not a joint: {name} is one number or a mapping of "
                                  f"{', '.join(joints)}")
        return tuple(self.number(arg, *keys, joint, non_negative=non_negative) for joint in joints)

    def vector(self, arg: str, *keys: str, length: int) -> tuple:
        value = self.node(arg, *keys)
        if not (isinstance(value, list) and len(value) == length
                and all(is_number(v) and math.isfinite(v) and abs(v) <= MAX_MAGNITUDE for v in value)):
            raise self.error(arg, f"{'.'.join(keys)} must be a list of {length} finite numbers of magnitude at most "
                                  f"{MAX_MAGNITUDE:g}, got {value!r}")
        return tuple(value)

    def text(self, arg: str, *keys: str) -> str:
        value = self.node(arg, *keys)
        if not isinstance(value, str) or not value.strip():
            raise self.error(arg, f"{'.'.join(keys)} must be a non-empty text, got {value!r}")
        return value

    def interval(self, arg: str, prefix: tuple[str, ...], joint: str) -> tuple[float, float]:
        lo = self.number(arg, *prefix, joint, "lower")
        hi = self.number(arg, *prefix, joint, "upper")
        name = ".".join((*prefix, joint))
        for side, value in (("lower", lo), ("upper", hi)):
            if abs(value) > JOINT_LIMIT_BOUND:
                raise self.error(arg, f"{name}.{side} must be within one turn (|limit| <= 2 pi rad), got {value!r}")
        if lo >= hi:
            raise self.error(arg, f"{name}.lower must be below {name}.upper")
        return lo, hi
