"""The stylus gimbal held still: a URDF whose gimbal joints are fixed at given angles.

The arm's 3-DoF dynamics (Phantom, simulate, Device, the identification) carry the gimbal and
the stylus as a rigid load on the forearm, at the configuration's ``gimbal.locked_at``: their
URDF is the description's with joint4..joint6 made fixed joints whose origins hold the
rotation the angles give (pinocchio.exp3 about each joint's axis). At those angles every
link's pose, and so the arm's mass matrix and gravity, equal the six-joint model's.
"""

from __future__ import annotations

import dataclasses
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin

from phantom_pin.config.types import GIMBAL_JOINTS
from phantom_pin.description.urdf import child_link, parse, read
from phantom_pin.exceptions import ParameterFileError

if TYPE_CHECKING:
    from phantom_pin.description.build import Description


def locked(urdf_xml: str, prefix: str, angles: Sequence[float]) -> str:
    """``urdf_xml`` with its gimbal joints (``prefix`` + GIMBAL_JOINTS) fixed at ``angles``
    (rad): each becomes a fixed joint whose origin rpy is its own composed with its rotation;
    its axis and limit are dropped. ParameterFileError if a gimbal joint is missing."""
    root = parse(urdf_xml)
    for name, angle in zip(GIMBAL_JOINTS, angles):
        joint = root.find(f"joint[@name='{prefix}{name}']")
        if joint is None:
            raise ParameterFileError(f"URDF: no gimbal joint {prefix}{name} to lock")
        axis_element, origin = joint.find("axis"), joint.find("origin")
        axis = [float(v) for v in (axis_element.get("xyz", "1 0 0") if axis_element is not None else "1 0 0").split()]
        if origin is None:
            origin = ET.SubElement(joint, "origin", {"xyz": "0 0 0"})
        rpy = np.array([float(v) for v in origin.get("rpy", "0 0 0").split()])
        direction = np.asarray(axis, float) / np.linalg.norm(axis)
        turned = pin.rpy.rpyToMatrix(rpy) @ pin.exp3(direction * float(angle))  # Rodrigues' formula
        origin.set("rpy", " ".join(repr(float(v)) for v in pin.rpy.matrixToRpy(turned)))
        joint.set("type", "fixed")
        for tag in ("axis", "limit", "dynamics"):
            for element in joint.findall(tag):
                joint.remove(element)
    return ET.tostring(root, encoding="unicode")


def arm_only(description: Description) -> Description:
    """``description`` without its stylus gimbal: the URDF's subtree from joint4 down removed
    (the gimbal's joints, links and the stylus frames) and ``config.gimbal`` None; the arm the
    report's closed form describes (phantom_pin.dynamics.verification checks it). A description without
    a gimbal is returned as it is."""
    config = description.config
    if config.gimbal is None:
        return description
    tree = read(description.urdf)
    root, children = tree.root, tree.children
    first = root.find(f"joint[@name='{description.prefix}{GIMBAL_JOINTS[0]}']")
    if first is None:
        raise ParameterFileError(f"URDF: no gimbal joint {description.prefix}{GIMBAL_JOINTS[0]}")
    doomed = [first]
    while doomed:
        joint = doomed.pop()
        link = child_link(joint)
        doomed.extend(children.get(link, []))
        root.remove(joint)
        element = root.find(f"link[@name='{link}']")
        if element is not None:
            root.remove(element)
    return dataclasses.replace(description, urdf=ET.tostring(root, encoding="unicode"),
                               config=dataclasses.replace(config, gimbal=None))
