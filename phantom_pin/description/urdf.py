"""The one reader of a URDF text: ``parse`` (the document, ParameterFileError naming the source
where it is not well-formed XML) and ``read`` (a view of its tree: links by name, joints, each
link's child joints, the root link, joints in topological order, transmissions by joint).

The physical checks, the mimic tags, the gimbal's locking and removal, the MJCF and the C
header's generator all read a URDF through this module.
"""

from __future__ import annotations

import dataclasses
import xml.etree.ElementTree as ET

from phantom_pin.exceptions import ParameterFileError


def parse(urdf_xml: str, source: str = "URDF") -> ET.Element:
    """The root element of a URDF text; ParameterFileError naming ``source`` if it is not
    well-formed XML."""
    try:
        return ET.fromstring(urdf_xml)
    except ET.ParseError as error:
        raise ParameterFileError(f"{source}: not well-formed XML ({error})") from error


def child(element: ET.Element, path: str) -> ET.Element:
    """The sub-element at ``path`` that describe()'s URDF always has; ParameterFileError naming
    what is missing otherwise (a URDF of one's own)."""
    found = element.find(path)
    if found is None:
        raise ParameterFileError(f"URDF: <{element.tag} name={element.get('name')!r}> has no <{path}>")
    return found


def attribute(element: ET.Element, name: str) -> str:
    """The attribute ``name`` of ``element``, which describe()'s URDF always gives;
    ParameterFileError otherwise."""
    value = element.get(name)
    if value is None:
        raise ParameterFileError(f"URDF: <{element.tag} name={element.get('name')!r}> has no {name} attribute")
    return value


def parent_link(joint: ET.Element) -> str:
    """The name of a joint's parent link."""
    return attribute(child(joint, "parent"), "link")


def child_link(joint: ET.Element) -> str:
    """The name of a joint's child link."""
    return attribute(child(joint, "child"), "link")


@dataclasses.dataclass(frozen=True)
class Urdf:
    """A URDF's tree: ``root`` (the document), ``links`` (by name, document order), ``joints``
    (document order), ``children`` (each link's child joints, document order), ``base`` (the
    one link that is no joint's child) and ``transmissions`` (by joint name)."""

    root: ET.Element
    links: dict[str, ET.Element]
    joints: list[ET.Element]
    children: dict[str, list[ET.Element]]
    base: str
    transmissions: dict[str, ET.Element]

    @property
    def name(self) -> str:
        """The robot's name."""
        return attribute(self.root, "name")

    def ordered(self) -> list[ET.Element]:
        """The joints breadth first from ``base``: every joint after its parent link's own joint."""
        order: list[ET.Element] = []
        frontier = [self.base]
        while frontier:
            here = frontier.pop(0)
            for joint in self.children.get(here, []):
                order.append(joint)
                frontier.append(child_link(joint))
        return order


def read(urdf_xml: str, source: str = "URDF") -> Urdf:
    """The tree of a URDF text (Urdf); ParameterFileError for malformed XML, a joint without a
    parent or child link, or not exactly one root link."""
    root = parse(urdf_xml, source)
    links = {attribute(link, "name"): link for link in root.findall("link")}
    joints = root.findall("joint")
    children: dict[str, list[ET.Element]] = {}
    for joint in joints:
        children.setdefault(parent_link(joint), []).append(joint)
    child_links = {child_link(joint) for joint in joints}
    bases = [name for name in links if name not in child_links]
    if len(bases) != 1:
        raise ParameterFileError(f"{source}: expected one root link, got {bases}")
    transmissions = {attribute(child(t, "joint"), "name"): t for t in root.findall("transmission")}
    return Urdf(root, links, joints, children, bases[0], transmissions)
