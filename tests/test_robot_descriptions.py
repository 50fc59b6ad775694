"""phantom_pin.robot_descriptions: robot_descriptions.py's attributes, for every model, naming
the committed files; and what a loader without mimic=True makes of them."""

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from phantom_pin import Phantom, robot_descriptions
from phantom_pin.config import DEFAULT, MODELS, models

ATTRIBUTES = ("PACKAGE_PATH", "REPOSITORY_PATH", "URDF_PATH", "SRDF_PATH", "MJCF_PATH", "SCENE_PATH",
              "XACRO_PATH", "CONFIG_PATH")


@pytest.mark.parametrize("name", models())
def test_every_model_has_the_attributes_naming_its_committed_files(name):
    files = getattr(robot_descriptions, name)
    model = MODELS[name]
    expected = {"URDF_PATH": model.urdf, "SRDF_PATH": model.srdf, "MJCF_PATH": model.mjcf,
                "SCENE_PATH": model.scene, "XACRO_PATH": model.urdf_xacro, "CONFIG_PATH": model.config}
    for attribute in ATTRIBUTES:
        value = getattr(files, attribute)
        assert isinstance(value, str) and Path(value).is_absolute() and Path(value).exists(), attribute
    for attribute, path in expected.items():
        assert Path(getattr(files, attribute)) == path
    assert Path(files.PACKAGE_PATH, "package.xml").is_file()
    assert Path(files.REPOSITORY_PATH, "robots", "phantom_description") == Path(files.PACKAGE_PATH)
    assert Path(files.URDF_PATH).is_relative_to(files.PACKAGE_PATH)
    # xacro XACRO_PATH *XACRO_ARGS is this model: the robot its URDF names
    import xacro
    # (a copy: xacro adds its arguments' defaults to the dict it is given)
    document = xacro.process_file(files.XACRO_PATH, mappings=dict(files.XACRO_ARGS))
    assert document.documentElement.getAttribute("name") == model.name == name


def test_the_module_itself_is_the_default_model():
    for attribute in ATTRIBUTES:
        assert getattr(robot_descriptions, attribute) == getattr(getattr(robot_descriptions, DEFAULT), attribute)
    assert robot_descriptions.XACRO_ARGS == getattr(robot_descriptions, DEFAULT).XACRO_ARGS


def test_a_loader_without_mimic_opens_the_parallelogram():
    """pin.RobotWrapper.BuildFromURDF as robot_descriptions' and example-robot-data's loaders
    call it: seven independent joints; at the zero posture gravity then loads the passive
    joints, and the actuated joints' torques differ from the arm's."""
    robot = pin.RobotWrapper.BuildFromURDF(robot_descriptions.URDF_PATH)
    assert robot.model.nq == 7
    theta = np.array([0.2, 0.5, 0.9])
    q = np.zeros(7)
    q[:3] = theta                     # the passive joints left at zero: not the arm's posture
    gravity = pin.computeGeneralizedGravity(robot.model, robot.data, q)
    assert np.abs(gravity[3:]).max() > 1e-3
    assert not np.allclose(gravity[:3], Phantom().gravity(theta), rtol=1e-3)
    closed = pin.RobotWrapper.BuildFromURDF(robot_descriptions.URDF_PATH, mimic=True)
    assert closed.model.nq == 3


def test_the_touch_has_the_path_of_its_drivers_convention_urdf():
    """L16: no path named urdf/touch_driver.urdf. The Touch's DRIVER_URDF_PATH is that
    committed file, whose joints are the drivers' published joint_states names (waist, shoulder,
    elbow, yaw, pitch, roll: fsuarez6/phantom_omni omni_state.cpp, jhu-saw/sawSensablePhantom);
    the models without drivers' convention have none."""
    import xml.etree.ElementTree as ET

    path = Path(robot_descriptions.touch.DRIVER_URDF_PATH)
    assert path.is_absolute() and path == Path(robot_descriptions.touch.PACKAGE_PATH, "urdf",
                                                "touch_driver.urdf")
    joints = {joint.get("name") for joint in ET.parse(path).getroot().iter("joint")}
    assert {"waist", "shoulder", "elbow", "yaw", "pitch", "roll"} <= joints
    for name in models():
        if name != "touch":
            assert not hasattr(getattr(robot_descriptions, name), "DRIVER_URDF_PATH")
