"""Physical validity of a URDF document: the one check that generate_urdf, Phantom and load() share.

It inspects the URDF that xacro generated (or that load() reads), not the parameter
files, so that it judges the link inertias after every conversion the xacro applies
(report inertias about the shoulder moved to the centre of mass, rotor inertia moved
to the SRDF's armature) whatever that conversion becomes.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

import numpy as np

from phantom_pin.exceptions import ParameterFileError

#: Relative slack of the triangle inequality c <= a + b of the principal moments, as a
#: fraction of c: a thin rod (c = a + b exactly) passes after floating-point rounding.
TRIANGLE_TOLERANCE = 1e-9

#: The parameter-file keys that feed each link's <inertial>, by link name (without prefix).
_SOURCES = {
    "turret_link": "segment_g.mass, segment_g.inertia_*, actuation.motor.rotor_inertia, "
                   "transmission_ratio.joint1, hinge_pin.inertia.zz",
    "upper_arm_link": "segment_be.mass, segment_be.com, segment_be.inertia, "
                      "actuation.motor.rotor_inertia, transmission_ratio.joint2",
    "crank_link": "segment_df.mass, segment_df.com, segment_df.inertia, "
                  "actuation.motor.rotor_inertia, transmission_ratio.joint3, hinge_pin.mass",
    "crank_pin_link": "hinge_pin.mass, hinge_pin.inertia",
    "lower_bar_link": "segment_c.mass, segment_c.inertia, hinge_pin.mass",
    "forearm_pin_link": "hinge_pin.mass, hinge_pin.inertia",
    "forearm_link": "segment_a.mass, segment_a.inertia",
}
#: Attributes of each URDF primitive that are sizes (m).
_SIZES = {"cylinder": ("radius", "length"), "sphere": ("radius",), "box": ("size",)}


def _numbers(text: str | None, count: int) -> list[float] | None:
    try:
        values = [float(v) for v in (text or "").split()]
    except ValueError:
        return None
    return values if len(values) == count else None


def _fail(source: str, link: str, problem: str) -> ParameterFileError:
    """An error on a link's <inertial>, naming the keys that feed it where they are known."""
    feeds = next((keys for name, keys in _SOURCES.items() if link.endswith(name)), None)
    return ParameterFileError(f"{source}: link {link}: {problem}" + (f" (from {feeds})" if feeds else ""))


def _check_inertial(source: str, link: str, inertial: ET.Element) -> None:
    mass_tag, inertia_tag = inertial.find("mass"), inertial.find("inertia")
    mass = _numbers(None if mass_tag is None else mass_tag.get("value"), 1)
    if mass is None or not math.isfinite(mass[0]) or mass[0] <= 0:
        raise _fail(source, link, f"mass must be a positive number of kg, got "
                                  f"{None if mass_tag is None else mass_tag.get('value')!r}")
    names = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
    values = [_numbers(None if inertia_tag is None else inertia_tag.get(n, "0"), 1) for n in names]
    if any(v is None or not math.isfinite(v[0]) for v in values):
        raise _fail(source, link, "inertia needs six finite numbers ixx ixy ixz iyy iyz izz (kg m^2)")
    xx, xy, xz, yy, yz, zz = (v[0] for v in values)
    moments = np.linalg.eigvalsh(np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]]))
    listed = ", ".join(f"{m:.4g}" for m in moments)
    if moments[0] <= 0:
        raise _fail(source, link, f"inertia at the centre of mass is not positive definite "
                                  f"(principal moments {listed} kg m^2)")
    a, b, c = moments
    if c - (a + b) > TRIANGLE_TOLERANCE * c:
        raise _fail(source, link, f"principal moments of inertia at the centre of mass {listed} "
                                  f"kg m^2 break the triangle inequality (largest > sum of the others)")


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
    """Raise ParameterFileError (naming ``source``, the link, the problem and, for the
    PHANToM's links, the parameter-file keys that feed it) unless the URDF is physical:

    - every <inertial> has a finite mass > 0 and a positive definite inertia tensor at
      the centre of mass (the URDF stores six numbers, so the tensor is symmetric by
      construction), whose principal moments a <= b <= c satisfy the triangle
      inequality c <= a + b up to TRIANGLE_TOLERANCE * c;
    - every <cylinder> radius and length, <box> size and <sphere> radius of a <visual>
      or <collision> is finite and > 0 (m).

    Links without <inertial> (pure frames) are accepted.
    """
    try:
        root = ET.fromstring(urdf_xml)
    except ET.ParseError as error:
        raise ParameterFileError(f"{source}: not well-formed XML ({error})") from error
    for link in root.iter("link"):
        name = link.get("name", "?")
        inertial = link.find("inertial")
        if inertial is not None:
            _check_inertial(source, name, inertial)
        for element in link:
            if element.tag in ("visual", "collision"):
                _check_geometry(source, name, element)
