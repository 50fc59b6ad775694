"""codegen.tree: the tree the header's generator walks, read from each committed URDF, against
yourdfpy's reading of the same file (joints' links, placements as 4x4 by Pinocchio's rpy, unit
axes, mimic coupling; links' masses, centres of mass and inertias: exact, 1e-15 for the rotations
and normalised axes); the joints in topological order; the joints it does not cover refused."""

import numpy as np
import pinocchio as pin
import pytest
import yourdfpy

from phantom_pin import ParameterFileError, config
from phantom_pin.codegen.tree import ARM_JOINTS, read_tree

GIMBAL = ("joint4", "joint5", "joint6")


@pytest.mark.parametrize("name, independent", [("premium_1_5", ARM_JOINTS), ("premium_1_5_cad", ARM_JOINTS),
                                               ("touch", ARM_JOINTS + GIMBAL)])
def test_the_tree_is_the_urdf_as_yourdfpy_reads_it(name, independent):
    """(The Touch's gimbal joints as coordinates 3-5: the header reads its arm with them held.)"""
    path = config.MODELS[name].urdf
    root, joints, links = read_tree(path.read_text(encoding="utf-8"), "", independent)
    reference = yourdfpy.URDF.load(str(path), build_scene_graph=False, load_meshes=False).robot
    theirs = {j.name: j for j in reference.joints}
    assert sorted(j.name for j in joints) == sorted(theirs)
    for joint in joints:
        other = theirs[joint.name]
        assert (joint.parent, joint.child) == (other.parent, other.child)
        placement = np.eye(4)
        placement[:3, :3], placement[:3, 3] = pin.rpy.rpyToMatrix(*joint.rpy), joint.xyz
        np.testing.assert_allclose(placement, other.origin, rtol=0, atol=1e-15, err_msg=joint.name)
        if other.type == "fixed":
            assert joint.axis is None and joint.coordinate is None
            continue
        np.testing.assert_allclose(joint.axis, other.axis / np.linalg.norm(other.axis), rtol=0, atol=1e-15)
        primary = other.mimic.joint if other.mimic else other.name
        assert joint.coordinate == independent.index(primary), joint.name
        assert joint.multiplier == (other.mimic.multiplier if other.mimic else 1.0)
        assert joint.offset == (other.mimic.offset if other.mimic else 0.0)
    inertial = {link.name: link.inertial for link in reference.links if link.inertial is not None}
    assert sorted(links) == sorted(inertial)
    for link, read in links.items():
        other = inertial[link]
        assert read.mass == other.mass and np.array_equal(read.com, other.origin[:3, 3])
        np.testing.assert_allclose(pin.rpy.rpyToMatrix(*read.rpy), other.origin[:3, :3], rtol=0, atol=1e-15)
        ixx, ixy, ixz, iyy, iyz, izz = read.inertia
        assert np.array_equal([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]], other.inertia), link
    # topological: every joint's parent is the root or an earlier joint's child
    seen = {root}
    for joint in joints:
        assert joint.parent in seen, joint.name
        seen.add(joint.child)
    assert root not in {j.child for j in joints}


URDF = """<robot name="r"><link name="a"/><link name="b"/><link name="c"/>
<joint name="joint1" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 2"/></joint>
<joint name="slide" type="{kind}"><parent link="b"/><child link="c"/>{mimic}</joint></robot>"""


def test_the_joints_it_does_not_cover_are_refused():
    """A prismatic joint, a joint that mimics no arm joint: ParameterFileError naming the joint;
    a revolute one mimicking joint1 is its coordinate 0 with its multiplier, the axis
    normalised (0 0 2 -> 0 0 1), origin and axis defaults 0 0 0 and 1 0 0."""
    with pytest.raises(ParameterFileError, match="^joint slide: codegen covers revolute and fixed joints, "
                                                   "not prismatic"):
        read_tree(URDF.format(kind="prismatic", mimic=""), "", ("joint1",))
    with pytest.raises(ParameterFileError, match="^joint slide: codegen covers the joints joint1 .*not elbow"):
        read_tree(URDF.format(kind="revolute", mimic='<mimic joint="elbow"/>'), "", ("joint1",))
    root, joints, links = read_tree(URDF.format(kind="revolute", mimic='<mimic joint="joint1" multiplier="-1"/>'),
                                    "", ("joint1",))
    assert root == "a" and links == {}
    first, slide = joints
    assert first.axis == (0.0, 0.0, 1.0) and first.xyz == (0.0, 0.0, 0.0) and first.rpy == (0.0, 0.0, 0.0)
    assert slide.axis == (1.0, 0.0, 0.0) and slide.coordinate == 0 and slide.multiplier == -1.0 and slide.offset == 0
