"""description.urdf: the one URDF reader against yourdfpy on each committed URDF (links, joints in
document order with their parent and child links, the root; the transmissions by joint against ElementTree), its
breadth-first order checked by hand on a small tree, and its refusals naming what is wrong."""

import xml.etree.ElementTree as ElementTree

import pytest
import yourdfpy

from phantom_pin import ParameterFileError, config
from phantom_pin.description.urdf import child_link, parent_link, read


@pytest.mark.parametrize("name", ["premium_1_5", "premium_1_5_cad", "touch"])
def test_the_tree_is_yourdfpys(name):
    path = config.MODELS[name].urdf
    tree = read(path.read_text(encoding="utf-8"))
    other = yourdfpy.URDF.load(str(path), build_scene_graph=True, load_meshes=False)
    robot = other.robot
    assert tree.name == robot.name
    assert list(tree.links) == [link.name for link in robot.links]
    assert [(j.get("name"), parent_link(j), child_link(j)) for j in tree.joints] == \
        [(j.name, j.parent, j.child) for j in robot.joints]
    assert tree.base == other.base_link
    # (yourdfpy skips these transmissions: ElementTree's XPath instead)
    written = ElementTree.parse(path).getroot().iterfind("transmission")
    assert {joint: t.get("name") for joint, t in tree.transmissions.items()} == \
        {t.find("joint").get("name"): t.get("name") for t in written}
    assert set(tree.transmissions) == {"joint1", "joint2", "joint3"}
    # breadth first: each joint after the joint whose child is its parent
    order = [j.get("name") for j in tree.ordered()]
    assert sorted(order) == sorted(j.name for j in robot.joints)
    reached = {tree.base}
    for joint in tree.ordered():
        assert parent_link(joint) in reached
        reached.add(child_link(joint))


TREE = """<robot name="r">{links}
<joint name="cd" type="fixed"><parent link="c"/><child link="d"/></joint>
<joint name="ab" type="fixed"><parent link="a"/><child link="b"/></joint>
<joint name="ac" type="fixed"><parent link="a"/><child link="c"/></joint>
<joint name="be" type="fixed"><parent link="b"/><child link="e"/></joint></robot>"""
LINKS = "".join(f'<link name="{n}"/>' for n in "abcde")


def test_breadth_first_from_the_root():
    """a -> (b, c), b -> e, c -> d, written out of order: breadth first ab, ac, be, cd."""
    tree = read(TREE.format(links=LINKS))
    assert tree.base == "a" and [j.get("name") for j in tree.ordered()] == ["ab", "ac", "be", "cd"]
    assert [j.get("name") for j in tree.children["a"]] == ["ab", "ac"]


def test_the_refusals_name_what_is_wrong():
    with pytest.raises(ParameterFileError, match="^my.urdf: not well-formed XML"):
        read("<robot><link></robot>", "my.urdf")
    with pytest.raises(ParameterFileError, match=r"^my.urdf: expected one root link, got \['a', 'f'\]"):
        read(TREE.format(links=LINKS + '<link name="f"/>'), "my.urdf")
    with pytest.raises(ParameterFileError, match="<joint name='j'> has no <parent>"):
        read('<robot name="r"><link name="a"/><joint name="j"><child link="a"/></joint></robot>')
    with pytest.raises(ParameterFileError, match="<child name=None> has no link attribute"):
        read('<robot name="r"><link name="a"/><joint name="j"><parent link="a"/><child/></joint></robot>')
    with pytest.raises(ParameterFileError, match="<robot name=None> has no name attribute"):
        _ = read('<robot><link name="a"/></robot>').name
