"""The description's files for other tools' loaders, in the style of robot_descriptions.py:
absolute paths as strings, with no need to know the package's layout.

    from phantom_pin import robot_descriptions as rd
    rd.URDF_PATH                # the default model's (premium_1_5) URDF
    rd.touch.MJCF_PATH          # the same attributes per model (phantom_pin.models())

Each model (``premium_1_5``, ``premium_1_5_cad``, ``touch``, and the module itself for the
default) has PACKAGE_PATH (robots/phantom_description, the ROS package), REPOSITORY_PATH (the
folder holding robots/), URDF_PATH, SRDF_PATH, MJCF_PATH (the arm), SCENE_PATH (the MJCF
scene: floor, light, table), XACRO_PATH (the top-level xacro, one for every model) with
XACRO_ARGS (the xacro arguments that select the model, a dict as robot_descriptions.py's:
``xacro.process_file(XACRO_PATH, mappings=XACRO_ARGS)``, or ``xacro XACRO_PATH model:=NAME``) and
CONFIG_PATH (its YAML). The
Touch, whose ROS drivers publish joint_states in their own convention, also has
DRIVER_URDF_PATH (urdf/touch_driver.urdf: the same arm jointed as the older drivers' waist,
shoulder, elbow, yaw, pitch, roll, phantom_pin.interfaces.conventions.FIXED_CONVENTION, for
robot_state_publisher; phantom-pin urdf --convention driver; kinisi's and CalaW's drivers publish
the waist with the other sign: docs/ros2.md).

Build a Pinocchio model from URDF_PATH with ``mimic=True`` (or use phantom_pin.load): without
it, as robot_descriptions' and example-robot-data's Pinocchio loaders build, the four passive
joints of the parallelogram become independent (nq = 7), the mechanism is open, and its
dynamics are not the arm's.
"""

from __future__ import annotations

import types

from phantom_pin._paths import DESCRIPTION_DIR
from phantom_pin.config.models import DEFAULT, MODELS

PACKAGE_PATH = str(DESCRIPTION_DIR)
REPOSITORY_PATH = str(DESCRIPTION_DIR.parent.parent)


def _files(name: str, driver: bool = False) -> types.SimpleNamespace:
    model = MODELS[name]
    files = types.SimpleNamespace(
        PACKAGE_PATH=PACKAGE_PATH, REPOSITORY_PATH=REPOSITORY_PATH, URDF_PATH=str(model.urdf),
        SRDF_PATH=str(model.srdf), MJCF_PATH=str(model.mjcf), SCENE_PATH=str(model.scene),
        XACRO_PATH=str(model.urdf_xacro), XACRO_ARGS=model.xacro_mappings, CONFIG_PATH=str(model.config))
    if driver:  # the drivers' convention (description.build.driver_urdf), committed beside the URDF
        files.DRIVER_URDF_PATH = str(model.urdf.with_name(f"{model.name}_driver.urdf"))
    return files


premium_1_5 = _files("premium_1_5")
premium_1_5_cad = _files("premium_1_5_cad")
touch = _files("touch", driver=True)
_DEFAULT = _files(DEFAULT)
URDF_PATH, SRDF_PATH, MJCF_PATH = _DEFAULT.URDF_PATH, _DEFAULT.SRDF_PATH, _DEFAULT.MJCF_PATH
SCENE_PATH, XACRO_PATH, CONFIG_PATH = _DEFAULT.SCENE_PATH, _DEFAULT.XACRO_PATH, _DEFAULT.CONFIG_PATH
XACRO_ARGS = _DEFAULT.XACRO_ARGS
