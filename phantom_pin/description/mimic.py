"""A URDF's <mimic> tags: which joints follow which, by what multiplier and offset; read by
the MJCF (its joint equalities) and by the dynamics' Coupling (the tree model's map)."""

from __future__ import annotations

import dataclasses
import xml.etree.ElementTree as ET

from phantom_pin.description.urdf import parse
from phantom_pin.exceptions import ParameterFileError


@dataclasses.dataclass(frozen=True)
class Mimic:
    """One <mimic> tag: angle(joint) = multiplier * angle(primary) + offset (rad or m)."""

    joint: str
    primary: str
    multiplier: float
    offset: float


def read_mimic_tags(urdf_xml: str) -> dict[str, Mimic]:
    """The <mimic> tags of a URDF document, keyed by the mimicking joint's name."""
    return mimic_tags(parse(urdf_xml))


def mimic_tags(root: ET.Element) -> dict[str, Mimic]:
    """The <mimic> tags of a parsed URDF (phantom_pin.description.urdf.parse), keyed by the
    mimicking joint's name."""
    mimics = {}
    for joint in root.findall("joint"):
        tag = joint.find("mimic")
        if tag is not None:
            name, primary = joint.get("name"), tag.get("joint")
            if name is None or primary is None:
                raise ParameterFileError(f"URDF: a joint with a <mimic> needs a name and the mimic a joint "
                                         f"(joint {name!r}, mimic of {primary!r})")
            mimics[name] = Mimic(name, primary, float(tag.get("multiplier", 1.0)), float(tag.get("offset", 0.0)))
    return mimics
