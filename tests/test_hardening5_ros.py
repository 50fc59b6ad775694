"""Hardening 5 (issue 42), the ROS and driver conventions: phantom_pin.drivers' HD_CURRENT_TRANSFORM
and gimbal joint states, and the ROS node's computation (phantom_pin.ros2.Bridge), each against
something written out here from the drivers' published formulas, OpenHaptics' guide or the
report's closed form."""

from __future__ import annotations

import math

import numpy as np
import pytest

from phantom_pin import Phantom, closed_form, drivers, ros2
from phantom_pin.config import read
from phantom_pin.exceptions import InvalidInputError
from test_ros2 import DRIVER, driver_states, expected  # the closed form's reference for the node


def rodrigues(axis: np.ndarray, angle: float) -> np.ndarray:
    """The rotation by ``angle`` (rad) about the unit ``axis``: I + sin K + (1 - cos) K^2."""
    x, y, z = axis / np.linalg.norm(axis)
    k = np.array([[0, -z, y], [z, 0, -x], [-y, x, 0]])
    return np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * k @ k


def transform(rotation: np.ndarray, translation_mm) -> np.ndarray:
    """A 4x4 homogeneous transform (translation in mm)."""
    out = np.eye(4)
    out[:3, :3], out[:3, 3] = rotation, translation_mm
    return out


ROTATION = rodrigues(np.array([0.3, -0.5, 0.8]), 0.9)


# -- M3 and the mutations of drivers.py ------------------------------------------------------------

@pytest.mark.parametrize("pose", [
    "abc",                                                          # was a bare ValueError
    transform(1.1 * ROTATION, [10, 20, 30]) * [[1], [1], [1], [1]],  # scaled: was accepted
    transform(ROTATION, [1e308, 0, 0]) / 1000,                      # 1e305 m: inf mm came back
    transform(ROTATION @ np.diag([-1.0, 1, 1]), [0, 0, 0]),         # a mirror (det -1)
    [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0]],                     # 3x4
])
def test_openhaptics_transform_from_pose_refuses_what_is_not_a_finite_rigid_pose(pose):
    """M3: each refused with InvalidInputError naming ``pose``."""
    with pytest.raises(InvalidInputError) as error:
        drivers.openhaptics_transform_from_pose(pose)
    assert error.value.argument == "pose"


def test_a_mirrored_hd_current_transform_is_refused():
    """Mutation (drivers): a mirrored HD_CURRENT_TRANSFORM (an orthogonal rotation part of
    determinant -1, which R R^T = I alone lets through) was accepted."""
    for mirror in (np.diag([-1.0, 1, 1]), -np.eye(3)):
        rotation = ROTATION @ mirror
        assert np.allclose(rotation @ rotation.T, np.eye(3), atol=1e-12) and np.linalg.det(rotation) < 0
        flat = transform(rotation, [12.0, -70.0, -50.0]).T.ravel()   # column-major
        with pytest.raises(InvalidInputError) as error:
            drivers.pose_from_openhaptics_transform(flat)
        assert error.value.argument == "transform"


def test_a_row_major_hd_current_transform_is_refused():
    """Mutation (drivers): the last-row check removed, a row-major transform (its translation
    read as the last row, its rotation transposed, still proper) was accepted. Column-major,
    OpenHaptics' order (the translation at 12..14), the same numbers give the pose in m."""
    matrix = transform(ROTATION, [12.0, -70.0, -50.0])
    with pytest.raises(InvalidInputError) as error:
        drivers.pose_from_openhaptics_transform(matrix.ravel())        # row-major
    assert error.value.argument == "transform"
    flat = matrix.T.ravel()
    assert np.array_equal(flat[12:15], [12.0, -70.0, -50.0])
    assert np.abs(drivers.pose_from_openhaptics_transform(flat)[:3, :3] - ROTATION).max() < 1e-15


def test_omni_firewire_gimbal_rates_convert_without_the_offsets():
    """Mutation (drivers): omni_firewire's gimbal rates read back with the angle offsets
    subtracted. fsuarez6/phantom_omni omni_state.cpp 188-193 publishes yaw = pi - g1, pitch =
    -g2 - 3 pi / 4, roll = -g3 - pi, written out here: the rates of a motion g(t) are the finite
    difference of those positions (the map is affine: exact up to rounding, 1e-6 rad/s)."""
    rng = np.random.default_rng(42)
    g0, rate, h = rng.uniform(-0.5, 0.5, 3), rng.uniform(-2, 2, 3), 1e-3

    def published(g):
        return np.array([math.pi - g[0], -g[1] - 3 * math.pi / 4, -g[2] - math.pi])

    published_rate = (published(g0 + rate * h) - published(g0)) / h
    names = ["roll", "yaw", "pitch"]
    order = [2, 0, 1]
    back = drivers.gimbal_from_joint_state(names, published_rate[order], convention="omni_firewire", rates=True)
    assert np.abs(back - rate).max() < 1e-6
    positions = drivers.gimbal_from_joint_state(names, published(g0)[order], convention="omni_firewire")
    assert np.abs(positions - g0).max() < 1e-14


def test_gimbal_joint_states_with_a_prefix_read_their_own_names():
    """Mutation (drivers): gimbal joint states with a prefix were never tested. Two devices in
    one message (unprefixed and left_): each prefix reads its own three values (raw convention:
    the values themselves), and the names written carry it."""
    names = ["left_roll", "yaw", "left_yaw", "pitch", "left_pitch", "roll"]
    values = [0.3, -1.0, 0.1, -2.0, 0.2, -3.0]
    assert np.array_equal(drivers.gimbal_from_joint_state(names, values, prefix="left_"), [0.1, 0.2, 0.3])
    assert np.array_equal(drivers.gimbal_from_joint_state(names, values), [-1.0, -2.0, -3.0])
    written, position = drivers.joint_state_from_gimbal([0.1, 0.2, 0.3], prefix="left_")
    assert written == ["left_yaw", "left_pitch", "left_roll"] and np.array_equal(position, [0.1, 0.2, 0.3])
    with pytest.raises(InvalidInputError) as error:
        drivers.gimbal_from_joint_state(["yaw", "pitch", "roll"], [0, 0, 0], prefix="left_")
    assert error.value.argument == "names"


# -- M2, L15 and the mutations of ros2.py ----------------------------------------------------------


@pytest.fixture(scope="module")
def touch() -> Phantom:
    return Phantom.from_model("touch")


@pytest.mark.parametrize("names", [
    ["waist", "waist", "shoulder", "elbow"],
    ["waist", "shoulder", "elbow", "yaw", "pitch", "roll", "pitch"],
    ["joint1", "joint2", "joint3", "joint3"],
    ["joint1", "joint2", "joint3", "joint4", "joint5", "joint6", "joint4"],
])
def test_a_name_given_twice_is_refused_as_the_drivers_conversions_refuse_it(touch, names):
    """M2: the node took the last of a name given twice; drivers.theta_from_joint_state (and
    gimbal_from_joint_state) refuse it, naming the names: the node now drops it naming ``name``."""
    position = [0.1] * len(names)
    with pytest.raises(InvalidInputError) as error:
        ros2.Bridge(touch)(names, position)
    assert error.value.argument == "name"
    if names[0] == "waist":
        convert = drivers.theta_from_joint_state if len(names) == 4 else drivers.gimbal_from_joint_state
        with pytest.raises(InvalidInputError) as error:
            convert(names, position)
        assert error.value.argument == "names"


@pytest.mark.parametrize("gimbal_names", [("joint4", "joint5", "joint6"), ("yaw", "pitch", "roll")])
@pytest.mark.parametrize("arm_names", ["driver", "model"])
def test_the_gimbal_is_read_under_either_names_with_either_arm(touch, arm_names, gimbal_names):
    """M2: the gimbal sent under the model's own names (joint4..joint6) beside the drivers' arm
    names was silently ignored (gravity at locked_at, no stylus pose). Each pairing now gives the
    closed form's gravity with the gimbal's reference load and Ubitrack's stylus pose (1e-12)."""
    bridge = ros2.Bridge(touch)
    for position in driver_states(5, seed=11):
        reference = expected(touch.config.report, position)
        waist, shoulder, elbow, *g = position
        arm = ((["waist", "shoulder", "elbow"], [waist, shoulder, elbow]) if arm_names == "driver"
               else (["joint1", "joint2", "joint3"], [waist, shoulder, shoulder + elbow]))
        out = bridge([*gimbal_names, *arm[0]], [*g, *arm[1]])
        e = reference["effort"]     # conjugate to (waist, shoulder, elbow); the model's names get tau itself
        effort = e if arm_names == "driver" else np.array([e[0], e[1] - e[2], e[2]])
        assert np.abs(out.effort - effort).max() < 1e-12
        assert out.stylus is not None and np.abs(out.stylus - reference["stylus"]).max() < 1e-12


@pytest.mark.parametrize("names", [["waist", "shoulder", "elbow", "yaw"], ["waist", "shoulder", "elbow", "joint5"],
                                   ["joint1", "joint2", "joint3", "yaw", "pitch"],
                                   ["waist", "shoulder", "elbow", "yaw", "pitch", "roll", "joint4", "joint5",
                                    "joint6"]])
def test_some_of_the_gimbals_names_are_refused_naming_name(touch, names):
    """Mutation (ros2): a message with some of the gimbal's names raised KeyError (which the node
    does not catch: it died). Refused with InvalidInputError naming ``name``; so is the gimbal
    given twice, under both sets of names."""
    with pytest.raises(InvalidInputError) as error:
        ros2.Bridge(touch)(names, [0.1] * len(names))
    assert error.value.argument == "name"


def test_a_velocity_of_the_wrong_length_is_refused(touch):
    """L15: a velocity field of another length than the names was taken. One value per name, or
    none (the drivers that publish no velocity), is."""
    names, position = list(DRIVER), list(driver_states(1, seed=12)[0])
    bridge = ros2.Bridge(touch)
    for velocity in ([0.0, 0.1], [0.0] * 7):
        with pytest.raises(InvalidInputError) as error:
            bridge(names, position, velocity)
        assert error.value.argument == "velocity"
    assert np.array_equal(bridge(names, position, [0.5] * 6).effort, bridge(names, position).effort)


def test_the_bridge_of_a_model_without_a_gimbal_answers_from_the_closed_form():
    """Mutation (ros2): the Bridge of a model without a gimbal (premium_1_5) failing on every
    message passed, the node being tested on the Touch only. Against the report's closed form
    (eqs 10, 93-94) and the URDF's mimic tags written out here: the drivers' names (their yaw,
    pitch, roll ignored, there being no gimbal), the model's, 1e-12 (N m, m)."""
    config = read("premium_1_5")
    bridge = ros2.Bridge(Phantom.from_model("premium_1_5"))
    l1, l2 = config.kinematics.l1, config.kinematics.l2
    base_from_s = np.eye(4)                      # the macro's report_s: at (l1, 0, -l2), axes (y, z, x)
    base_from_s[:3, :3] = [[0, 0, 1], [1, 0, 0], [0, 1, 0]]
    base_from_s[:3, 3] = l1, 0, -l2
    rng = np.random.default_rng(13)
    lower, upper = np.array(config.limits.stops.lower), np.array(config.limits.stops.upper)
    for theta in rng.uniform(lower, upper, (20, 3)):
        tau = closed_form.gravity(theta, config.report)
        out = bridge(["yaw", "elbow", "shoulder", "pitch", "waist", "roll"],
                     [9.0, theta[2] - theta[1], theta[1], 9.0, theta[0], 9.0])
        assert out.stylus is None and out.names == ("waist", "shoulder", "elbow")
        assert np.abs(out.effort - [tau[0], tau[1] + tau[2], tau[2]]).max() < 1e-12
        assert np.abs(out.tip - base_from_s @ closed_form.forward_kinematics(theta, config.report)).max() < 1e-12
        assert np.abs(out.openhaptics - 1000 * tau * [-1, 1, 1]).max() < 1e-9
        model = {"joint1": theta[0], "joint2": theta[1], "joint3": theta[2], "crank_pin_a": -theta[2],
                 "crank_pin_b": theta[1], "forearm_pin_a": -theta[1], "forearm_pin_b": theta[2]}
        assert dict(zip(out.model_names, out.model_positions)) == pytest.approx(model, abs=1e-15)
        mine = bridge(["joint1", "joint2", "joint3"], list(theta))
        assert mine.stylus is None and np.abs(mine.effort - tau).max() < 1e-12


class _Publisher:
    def __init__(self) -> None:
        self.messages: list = []

    def publish(self, message) -> None:
        self.messages.append(message)


def test_the_openhaptics_topic_names_its_torques_turret_thigh_shin(touch):
    """Mutation (ros2): the OpenHaptics topic's joint names swapped (thigh/shin) passed. OpenHaptics'
    reference guide names its joints "Turet Left +, Thigh Up +, Shin Up +", in the order of
    HD_CURRENT_JOINT_ANGLES; its torque on each is 1000 (-tau1, tau2, tau3) mN m (SensAble's
    CommandJointTorque sample), tau the closed form's: each name carries its own joint's torque."""
    position = driver_states(1, seed=14)[0]
    out = ros2.Bridge(touch)(list(DRIVER), list(position))
    outputs = {role: _Publisher() for role in ("gravity_torque", "gravity_torque_openhaptics", "tip_pose",
                                               "stylus_pose", "model_joint_states")}
    from builtin_interfaces.msg import Time

    ros2._publish_outputs(outputs, out, Time(sec=1, nanosec=2), "", "left_")
    message = outputs["gravity_torque_openhaptics"].messages[0]
    torques = dict(zip(message.name, message.effort))
    reference = expected(touch.config.report, position)["openhaptics"]
    assert list(torques) == ["left_turret", "left_thigh", "left_shin"]
    assert [torques["left_turret"], torques["left_thigh"], torques["left_shin"]] == pytest.approx(
        reference, abs=1e-9)


# -- H5: OpenHaptics' origin -------------------------------------------------------------------------

#: The ranges of a real Touch's logged HD_CURRENT_TRANSFORM positions (mm, OpenHaptics'
#: coordinates; iLUVE69/Limb-Impedance-measurement-using-GeoMagic-Touch-Haptic-Device,
#: NoDrift_Batch1/2_data.csv, the stylus slid in a horizontal plane): facts about the file,
#: which has no licence and is not copied.
LOGGED = {"x": (-75.0, 57.0), "y": (-83.0, -62.0), "z": (-66.0, -39.0)}


def touch_stops_yaml() -> tuple[np.ndarray, np.ndarray, float, float]:
    """The Touch's stops as joint_limits.yaml states them (PyYAML): per joint, and coupled."""
    import yaml

    from helpers import CONFIG_DIR

    stops = yaml.safe_load((CONFIG_DIR.parent / "touch" / "joint_limits.yaml").read_text())["stops"]
    joints = ("joint1", "joint2", "joint3")
    return (np.array([stops[j]["lower"] for j in joints]), np.array([stops[j]["upper"] for j in joints]),
            stops["theta2_minus_theta3_max"], stops["theta3_minus_theta2_max"])


def reachable_inside_the_stops(position: np.ndarray, report) -> bool:
    """Whether the report's closed-form inverse kinematics (eqs 11-20, either elbow branch) puts
    the gimbal centre at ``position`` (m, frame s) with theta inside the Touch's stops (its YAML)."""
    from phantom_pin.exceptions import UnreachableTargetError

    lower, upper, below, above = touch_stops_yaml()
    for branch in ("report", "other"):
        try:
            theta = closed_form.inverse_kinematics(position, report, branch=branch)
        except UnreachableTargetError:
            return False
        assert np.abs(closed_form.forward_kinematics(theta, report)[:3, 3] - position).max() < 1e-12
        if (np.all(lower <= theta) and np.all(theta <= upper) and theta[1] - theta[2] <= below
                and theta[2] - theta[1] <= above):
            return True
    return False


def logged_box(n: int = 3) -> np.ndarray:
    """An n x n x n grid over the logged ranges (mm), its corners included."""
    axes = [np.linspace(*LOGGED[axis], n) for axis in "xyz"]
    return np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)


def test_the_logged_positions_of_a_real_touch_are_reached_inside_its_stops_from_the_estimated_origin():
    """H5: drivers took OpenHaptics' origin to be frame s's (Ubitrack's calibration model), with
    which a real Touch's logged positions need theta2 < 0 (the Touch's stop is 0). With
    gimbal.yaml's openhaptics_shoulder (Carrot404's base_ref, an estimate) every point of the
    logged box (a 3x3x3 grid, its corners included; the translation of an HD_CURRENT_TRANSFORM
    is the gimbal centre, the stylus frame's origin) maps to a gimbal-centre position that the
    report's inverse kinematics reaches inside the stops; with the origins equal none does."""
    report = read("touch").report
    for point in logged_box():
        flat = np.eye(4)
        flat[:3, 3] = point
        flat = flat.T.ravel()                                 # column-major, mm
        estimated = drivers.pose_from_openhaptics_transform(flat)[:3, 3]
        assert reachable_inside_the_stops(estimated, report), point
        equal = drivers.pose_from_openhaptics_transform(flat, origin=np.zeros(3))[:3, 3]
        assert not reachable_inside_the_stops(equal, report), point


def test_the_origin_is_gimbal_yamls_shoulder_less_the_shoulder_in_frame_s():
    """openhaptics_origin: gimbal.yaml's openhaptics_shoulder less the shoulder's position in
    frame s, which the report's forward kinematics places at (0, l2, -l1) (the zero posture's
    upper arm l1 along +z, forearm l2 along -y, from the shoulder to frame s's origin): read
    through the configuration, an override moves it, a value in mm and a model without a
    gimbal are refused naming the key and the argument."""
    import yaml

    from helpers import CONFIG_DIR
    from phantom_pin import describe
    from phantom_pin.exceptions import ParameterFileError

    stated = yaml.safe_load((CONFIG_DIR.parent / "touch" / "gimbal.yaml").read_text())["openhaptics_shoulder"]
    report = read("touch").report
    # the shoulder: the point every posture's elbow stays l1 from, on the joint-1 axis
    shoulder = np.array([0.0, report.l2, -report.l1])
    for theta in np.random.default_rng(15).uniform(-1, 1, (10, 3)):
        tip = closed_form.forward_kinematics(theta, report)[:3, 3]
        assert abs(np.linalg.norm(tip - shoulder) ** 2 - (report.l1**2 + report.l2**2
                                                          + 2 * report.l1 * report.l2 * math.sin(theta[2] - theta[1]))
                   ) < 1e-12
    assert np.abs(drivers.openhaptics_origin() - (np.array(stated) - shoulder)).max() < 1e-15
    assert np.array_equal(drivers.openhaptics_origin(Phantom.from_model("touch")), drivers.openhaptics_origin())
    moved = describe("touch", overrides={"openhaptics_shoulder.2": -0.2})
    assert np.abs(drivers.openhaptics_origin(moved) - drivers.openhaptics_origin() - [0, 0, -0.2 - stated[2]]
                  ).max() < 1e-15
    back = drivers.pose_from_openhaptics_transform(drivers.openhaptics_transform_from_pose(
        transform(ROTATION, [0.01, 0.02, 0.03]) / [[1], [1], [1], [1]], origin=drivers.openhaptics_origin(moved)),
        origin=drivers.openhaptics_origin(moved))
    assert np.abs(back[:3, 3] - [0.01, 0.02, 0.03]).max() < 1e-15
    with pytest.raises(ParameterFileError, match="openhaptics_shoulder"):
        describe("touch", overrides={"openhaptics_shoulder.2": -157})
    with pytest.raises(InvalidInputError) as error:
        drivers.openhaptics_origin(Phantom.from_model("premium_1_5"))
    assert error.value.argument == "phantom"
    with pytest.raises(InvalidInputError) as error:
        drivers.pose_from_openhaptics_transform(np.eye(4).ravel(), origin=[[0, 0, 0]])
    assert error.value.argument == "origin"
