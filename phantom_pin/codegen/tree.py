"""The URDF's tree as the header's generator walks it: joints in topological order with their
placements, axes and mimic coupling, and the links' inertials (read through
phantom_pin.description.urdf)."""

from __future__ import annotations

import dataclasses
import math
import xml.etree.ElementTree as ET

from phantom_pin.description.urdf import child_link, parent_link, read
from phantom_pin.exceptions import ParameterFileError

#: The independent joints the header covers: the arm's three (the report's theta1..theta3).
ARM_JOINTS = ("joint1", "joint2", "joint3")


@dataclasses.dataclass(frozen=True)
class Joint:
    name: str
    parent: str
    child: str
    xyz: tuple[float, float, float]
    rpy: tuple[float, float, float]
    axis: tuple[float, float, float] | None       # None: fixed
    coordinate: int | None = None                 # index of theta driving it (None: fixed)
    multiplier: float = 1.0
    offset: float = 0.0


@dataclasses.dataclass(frozen=True)
class Link:
    mass: float
    com: tuple[float, float, float]
    rpy: tuple[float, float, float]
    inertia: tuple[float, float, float, float, float, float]  # ixx ixy ixz iyy iyz izz


def _get(element: ET.Element, path: str, key: str, default: str | None = None) -> str:
    """The attribute ``key`` of ``element``'s child at ``path`` ("" for the element itself);
    ``default`` where absent; ParameterFileError if absent without a default."""
    found = element if not path else element.find(path)
    value = None if found is None else found.get(key)
    if value is None:
        if default is None:
            raise ParameterFileError(f"URDF {element.tag} {element.get('name')!r}: no {path or element.tag} {key}")
        return default
    return value


def _floats(text: str) -> tuple[float, float, float]:
    x, y, z = (float(v) for v in text.split())
    return x, y, z


def read_tree(urdf: str, prefix: str, independent: tuple[str, ...] = ARM_JOINTS
               ) -> tuple[str, list[Joint], dict[str, Link]]:
    """(root link, joints in topological order, links with an inertial) of a URDF text
    (phantom_pin.description.urdf.read); the joints ``independent`` (without ``prefix``) are the
    coordinates, in that order."""
    tree = read(urdf)
    links: dict[str, Link] = {}
    for name, link in tree.links.items():
        inertial = link.find("inertial")
        if inertial is not None:
            ixx, ixy, ixz, iyy, iyz, izz = (float(_get(inertial, "inertia", k, "0"))
                                            for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"))
            links[name] = Link(
                float(_get(inertial, "mass", "value")), _floats(_get(inertial, "origin", "xyz", "0 0 0")),
                _floats(_get(inertial, "origin", "rpy", "0 0 0")), (ixx, ixy, ixz, iyy, iyz, izz))
    arm = [prefix + name for name in independent]
    joints = {id(joint): _joint(joint, arm) for joint in tree.joints}
    return tree.base, [joints[id(joint)] for joint in tree.ordered()], links


def _joint(joint: ET.Element, arm: list[str]) -> Joint:
    """One URDF joint, its coordinate the index in ``arm`` of the joint it is or mimics."""
    name, kind = _get(joint, "", "name"), _get(joint, "", "type")
    xyz, rpy = _floats(_get(joint, "origin", "xyz", "0 0 0")), _floats(_get(joint, "origin", "rpy", "0 0 0"))
    parent, child = parent_link(joint), child_link(joint)
    if kind == "fixed":
        return Joint(name, parent, child, xyz, rpy, None)
    if kind not in ("revolute", "continuous"):
        raise ParameterFileError(f"joint {name}: codegen covers revolute and fixed joints, not {kind}")
    x, y, z = _floats(_get(joint, "axis", "xyz", "1 0 0"))
    norm = math.sqrt(x * x + y * y + z * z)
    primary = _get(joint, "mimic", "joint", name)
    multiplier = float(_get(joint, "mimic", "multiplier", "1"))
    offset = float(_get(joint, "mimic", "offset", "0"))
    if primary not in arm:
        raise ParameterFileError(f"joint {name}: codegen covers the joints {', '.join(arm)} "
                                 f"(and joints that mimic them), not {primary}")
    return Joint(name, parent, child, xyz, rpy, (x / norm, y / norm, z / norm), arm.index(primary),
                  multiplier, offset)
