"""Physical validity of a URDF document: every <inertial> passes the one physical check of a
link (phantom_pin.description.inertial.problem), every primitive has positive sizes.

describe() checks the links of a configuration before xacro runs (naming the parameter
keys) and the URDF xacro generated after; load() checks a URDF file it is given.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

from phantom_pin.description.inertial import Inertial, problem, tensor6, vector3
from phantom_pin.description.urdf import parse
from phantom_pin.exceptions import ParameterFileError

#: Attributes of each URDF primitive that are sizes (m).
_SIZES = {"cylinder": ("radius", "length"), "sphere": ("radius",), "box": ("size",)}


def _numbers(text: str | None, count: int) -> list[float] | None:
    try:
        values = [float(v) for v in (text or "").split()]
    except ValueError:
        return None
    return values if len(values) == count else None


def urdf_inertial(inertial: ET.Element) -> Inertial | None:
    """The Inertial of a URDF <inertial> (its origin's rpy must be zero), or None if a number
    is missing or malformed."""
    origin, mass, inertia = inertial.find("origin"), inertial.find("mass"), inertial.find("inertia")
    xyz = _numbers("0 0 0" if origin is None else origin.get("xyz", "0 0 0"), 3)
    rpy = _numbers("0 0 0" if origin is None else origin.get("rpy", "0 0 0"), 3)
    m = _numbers(None if mass is None else mass.get("value"), 1)
    values = [_numbers(None if inertia is None else inertia.get(f"i{k}", "0"), 1)
              for k in ("xx", "xy", "xz", "yy", "yz", "zz")]
    entries = [v[0] for v in values if v is not None]
    if xyz is None or rpy is None or any(rpy) or m is None or len(entries) != len(values):
        return None
    return Inertial(m[0], vector3(xyz), tensor6(entries))


def _check_geometry(source: str, link: str, element: ET.Element) -> None:
    for shape, attributes in _SIZES.items():
        for primitive in element.iter(shape):
            for attribute in attributes:
                text = primitive.get(attribute)
                values = _numbers(text, 3 if attribute == "size" else 1)
                if values is None or not all(math.isfinite(v) and v > 0 for v in values):
                    raise ParameterFileError(
                        f"{source}: link {link}: {element.tag} {shape} {attribute} must be positive "
                        f"(m), got {text!r} (from visual_parameters.yaml or kinematics.yaml)")


def check_urdf(urdf_xml: str, source: str = "URDF") -> None:
    """Raise ParameterFileError (naming ``source``, the link and the problem) unless the URDF
    is physical: every <inertial> has an origin without rotation and six finite numbers
    that pass phantom_pin.description.inertial.problem (positive mass, positive definite inertia at
    the centre of mass, the triangle inequality with MuJoCo's margin); every <cylinder>
    radius and length, <box> size and <sphere> radius is finite and > 0 (m).
    Links without <inertial> (pure frames) are accepted.
    """
    for link in parse(urdf_xml, source).iter("link"):
        name = link.get("name", "?")
        element = link.find("inertial")
        if element is not None:
            inertial = urdf_inertial(element)
            trouble = ("inertial needs an origin without rotation, a mass and six numbers ixx ixy "
                       "ixz iyy iyz izz" if inertial is None else problem(inertial))
            if trouble:
                raise ParameterFileError(f"{source}: link {name}: {trouble}")
        for child in link:
            if child.tag in ("visual", "collision"):
                _check_geometry(source, name, child)
