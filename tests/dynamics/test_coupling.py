"""The generic mimic adapter against Pinocchio's own mimic models of example-robot-data robots."""

from importlib.metadata import distribution
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from helpers import URDF_PATH
from phantom_pin.description.mimic import read_mimic_tags
from phantom_pin.dynamics.coupling import Coupling


def _robots_dir() -> Path:
    files = distribution("example-robot-data").files
    package_xml = next(f for f in files if f.name == "package.xml" and "example-robot-data" in str(f))
    return Path(package_xml.locate()).parent / "robots"


ROBOTS = ["panda_description/urdf/panda.urdf", "pr2_description/urdf/pr2.urdf",
          "tiago_pro_description/robots/tiago_pro.urdf", "baxter_description/urdf/baxter.urdf"]


@pytest.mark.parametrize("relative", ROBOTS)
def test_projection_equals_pinocchio_mimic_model(relative):
    xml = (_robots_dir() / relative).read_text()
    coupling = Coupling(xml)
    reduced, tree = coupling.reduced, coupling.tree
    assert coupling.mimics and reduced.nv == tree.nv - len(coupling.mimics)
    rd, td = reduced.createData(), tree.createData()
    rng = np.random.default_rng(3)
    lower = np.clip(np.nan_to_num(reduced.lowerPositionLimit, neginf=-3), -3, 3)
    upper = np.clip(np.nan_to_num(reduced.upperPositionLimit, posinf=3), -3, 3)
    for _ in range(20):
        q = pin.randomConfiguration(reduced, lower, upper)
        v, a = rng.normal(size=reduced.nv), rng.normal(size=reduced.nv)
        qt = coupling.configuration(q)
        m = pin.crba(reduced, rd, q)
        mt = pin.crba(tree, td, qt)
        np.testing.assert_allclose(np.triu(m), np.triu(coupling.project(np.triu(mt) + np.triu(mt, 1).T)), atol=1e-12)
        np.testing.assert_allclose(pin.rnea(reduced, rd, q, v, a),
                                   coupling.project_force(pin.rnea(tree, td, qt, coupling.tangent(v),
                                                                   coupling.tangent(a))),
                                   atol=1e-10)
        pin.computeJointJacobians(reduced, rd, q)
        pin.framesForwardKinematics(reduced, rd, q)
        pin.computeJointJacobians(tree, td, qt)
        pin.framesForwardKinematics(tree, td, qt)
        for frame in reduced.frames:
            j = pin.getFrameJacobian(reduced, rd, reduced.getFrameId(frame.name), pin.LOCAL_WORLD_ALIGNED)
            jt = pin.getFrameJacobian(tree, td, tree.getFrameId(frame.name), pin.LOCAL_WORLD_ALIGNED)
            np.testing.assert_allclose(j, coupling.project_jacobian(jt), atol=1e-12, err_msg=frame.name)


def test_phantom_coupling_matrix_comes_from_the_mimic_tags():
    coupling = Coupling(URDF_PATH.read_text())
    expected = np.zeros((7, 3))
    for row, column, value in [(0, 0, 1), (1, 1, 1), (2, 2, 1), (3, 2, -1), (4, 1, 1), (5, 1, -1), (6, 2, 1)]:
        expected[row, column] = value
    assert list(coupling.tree.names[1:]) == ["joint1", "joint2", "joint3", "crank_pin_a", "crank_pin_b",
                                             "forearm_pin_a", "forearm_pin_b"]
    np.testing.assert_array_equal(coupling.matrix, expected)
    assert set(read_mimic_tags(URDF_PATH.read_text())) == {"crank_pin_a", "crank_pin_b", "forearm_pin_a",
                                                           "forearm_pin_b"}
