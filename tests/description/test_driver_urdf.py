"""The Touch's URDF in the older ROS drivers' fixed convention (urdf/touch_driver.urdf,
drivers.FIXED_CONVENTION): their six joint_states drive it unchanged. Its link poses, in Pinocchio (mimic) and yourdfpy,
from joint_states written by the drivers' published formulas (waist = -angle1, shoulder =
angle2, elbow = angle3 - angle2, raw gimbal angles), equal ours in the report's convention
from the OpenHaptics angles they came from."""

from __future__ import annotations

import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pinocchio as pin
import yaml
import yourdfpy

from phantom_pin.config import MODELS
from phantom_pin.description.build import driver_urdf
from references import driver as driver_reference

DRIVER_URDF = MODELS["touch"].urdf.with_name("touch_driver.urdf")
TOUCH = MODELS["touch"].config
DRIVER_JOINTS = ("waist", "shoulder", "elbow", "yaw", "pitch", "roll")
OURS = ("joint1", "joint2", "joint3", "joint4", "joint5", "joint6")


def openhaptics_states(n: int, seed: int) -> np.ndarray:
    """``n`` seeded OpenHaptics angle sets (joint angles O1..O3, raw gimbal O4..O6, rad) inside
    the Touch's stops and gimbal ranges (read from its YAML): the posture a driver reads."""
    limits = yaml.safe_load((TOUCH / "joint_limits.yaml").read_text())["stops"]
    gimbal = yaml.safe_load((TOUCH / "gimbal.yaml").read_text())["joints"]
    rng = np.random.default_rng(seed)
    theta = rng.uniform([limits[j]["lower"] for j in OURS[:3]], [limits[j]["upper"] for j in OURS[:3]], (8 * n, 3))
    keep = ((theta[:, 1] - theta[:, 2] <= limits["theta2_minus_theta3_max"])
            & (theta[:, 2] - theta[:, 1] <= limits["theta3_minus_theta2_max"]))
    g = rng.uniform([gimbal[j]["lower"] for j in OURS[3:]], [gimbal[j]["upper"] for j in OURS[3:]], (n, 3))
    theta = theta[keep][:n]
    return np.concatenate([-theta[:, :1], theta[:, 1:], g], axis=1)  # O1 = -theta1


def driver_joint_states(o: np.ndarray) -> dict[str, float]:
    """What the older drivers publish for OpenHaptics' angles ``o``: sawSensablePhantom's formula
    (driver_reference.published, its source lines; the fsuarez6 lineage's arm is the same)."""
    names, positions = driver_reference.published("sawsensablephantom", o[:3], o[3:])
    assert names == list(DRIVER_JOINTS)
    return dict(zip(names, positions))


def report_state(o: np.ndarray) -> dict[str, float]:
    """Our joints of the same angles: theta = (-O1, O2, O3), joint4..joint6 = the raw gimbal."""
    return dict(zip(OURS, (-o[0], o[1], o[2], o[3], o[4], o[5])))


def pinocchio_links(urdf: str, state: dict[str, float]) -> dict[str, np.ndarray]:
    model = pin.buildModelFromXML(urdf, mimic=True)
    data = model.createData()
    q = pin.neutral(model)
    for name, value in state.items():
        q[model.joints[model.getJointId(name)].idx_q] = value
    pin.framesForwardKinematics(model, data, q)
    return {f.name: data.oMf[i].homogeneous for i, f in enumerate(model.frames) if f.type == pin.FrameType.BODY}


def test_the_committed_driver_urdf_is_fresh():
    assert DRIVER_URDF.read_text() == driver_urdf("touch")


def test_the_drivers_joint_states_move_every_link_as_ours_in_pinocchio_and_yourdfpy():
    """Every link's pose in base_link, 1e-12 m and 1e-12 in rotation, over 100 states; the
    driver URDF's independent joints are exactly the drivers' six."""
    driver, ours = DRIVER_URDF.read_text(), MODELS["touch"].urdf.read_text()
    robot = yourdfpy.URDF.load(str(DRIVER_URDF), build_scene_graph=True, load_meshes=False)
    assert tuple(robot.actuated_joint_names) == DRIVER_JOINTS
    reduced = pin.buildModelFromXML(driver, mimic=True)
    assert reduced.nq == 6 and {reduced.names[i] for i in range(1, reduced.njoints)} >= set(DRIVER_JOINTS)
    for o in openhaptics_states(100, seed=11):
        state = driver_joint_states(o)
        expected = pinocchio_links(ours, report_state(o))
        got = pinocchio_links(driver, state)
        assert set(got) == set(expected)
        robot.update_cfg(state)
        for link, pose in expected.items():
            assert np.abs(got[link] - pose).max() < 1e-12, link
            assert np.abs(robot.get_transform(link, "base_link") - pose).max() < 1e-12, link


def test_no_rounded_elbow_and_check_urdf_passes(tmp_path):
    """The lineage's URDFs round the elbow's rpy to -1.5; ours has no rotated joint origin in
    the arm at all; urdfdom parses the prefixed file."""
    assert "-1.5 " not in DRIVER_URDF.read_text()
    urdf = tmp_path / "driver.urdf"
    urdf.write_text(driver_urdf("touch", prefix="left_"))
    tool = Path(sys.executable).parent / "check_urdf"
    result = subprocess.run([str(tool if tool.exists() else "check_urdf"), str(urdf)], capture_output=True, text=True)
    assert result.returncode == 0 and "root Link: left_base_link" in result.stdout, result.stdout + result.stderr


def test_plain_xacro_with_convention_driver_gives_the_committed_file(tmp_path):
    """xacro phantom.urdf.xacro model:=touch convention:=driver (its default parameter files) is
    the committed driver URDF (comments aside); another convention, the drivers' convention of a
    model without a stylus gimbal (no driver publishes it) and an unknown model are refused,
    each naming what it refuses."""
    top = MODELS["touch"].urdf_xacro
    xacro = Path(sys.executable).parent / "xacro"

    def run(*arguments: str) -> subprocess.CompletedProcess:
        return subprocess.run([str(xacro), str(top), *arguments], capture_output=True, text=True, cwd=top.parent)

    result = run("model:=touch", "convention:=driver")
    assert result.returncode == 0, result.stderr
    assert ET.canonicalize(result.stdout, strip_text=True) == ET.canonicalize(DRIVER_URDF.read_text(), strip_text=True)
    for arguments, message in ((("model:=touch", "convention:=ros"), "convention must be report or driver"),
                               (("convention:=driver",), "written for the Touch (model:=touch)"),
                               (("model:=omni",), "model must be one of premium_1_5, premium_1_5_cad, touch")):
        bad = run(*arguments)
        assert bad.returncode != 0 and message in bad.stderr, (arguments, bad.stderr)


def test_a_model_whose_drivers_publish_no_convention_is_refused_in_one_line(capsys, tmp_path):
    """Only the Touch takes convention:=driver: the Premium is refused, naming the model, before
    xacro runs, and nothing is written."""
    from phantom_pin import InvalidInputError
    from phantom_pin.cli import main

    try:
        driver_urdf("premium_1_5")
    except InvalidInputError as error:
        assert error.argument == "model" and "Touch" in str(error)
    else:
        raise AssertionError("driver_urdf('premium_1_5') was not refused")
    target = tmp_path / "d.urdf"
    assert main(["urdf", "--convention", "driver", "-o", str(target)]) == 2
    assert len(capsys.readouterr().err.strip().splitlines()) == 1 and not target.exists()
