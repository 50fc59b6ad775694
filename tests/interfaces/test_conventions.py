"""phantom_pin.interfaces.conventions against the drivers' own published formulas, written out here:

- Ubitrack's forward kinematics of OpenHaptics' joint angles (Ubitrack/component_haptic_calibration,
  src/utHaptics/Function/PhantomForwardKinematics.h lines 101-103, without calibration offsets),
  against Phantom.from_model("touch")'s tip in the report's frame s;
- the ROS joint_states of fsuarez6/phantom_omni (omni_state.cpp: waist = -a1, shoulder = a2,
  elbow = a3 - a2) and of jhu-saw/sawSensablePhantom (mtsSensableHD.cpp: q[0] = -q[0]; q[2] -= q[1]);
- SensAble's CommandJointTorque sample: torque (mN m) = k (0 - angle) is a restoring spring;
- and power: the same motion does the same work in either convention;
- HD_CURRENT_TRANSFORM: a finite rigid pose, column-major, and its origin in OpenHaptics'
  coordinates (a real Touch's logged position ranges reached inside the stops from it).
"""

import math

import numpy as np
import pytest

from phantom_pin import Phantom, closed_form
from phantom_pin.config import read
from phantom_pin.config.sampling import sample_postures
from phantom_pin.exceptions import InvalidInputError
from phantom_pin.interfaces import conventions, profiles
from references import driver as driver_reference

L = 0.13335  # m, Ubitrack's default l1 = l2 ("defaults to Phantom Omni: 133.35mm")
GIMBAL = ("yaw", "pitch", "roll")


@pytest.fixture(scope="module")
def angles() -> np.ndarray:
    """200 seeded OpenHaptics joint angles (rad) of postures inside the Touch's stops."""
    theta = sample_postures(read("touch").limits, 200, np.random.default_rng(8), draws=800)
    return theta * np.array([-1.0, 1.0, 1.0])  # Ubitrack's (and OpenHaptics') angle 1 turns the other way


def ubitrack(a: np.ndarray) -> np.ndarray:
    """PhantomForwardKinematics.h's translation (m, OpenHaptics' axes), offsets zero."""
    s1, c1, s2, c2, s3, c3 = np.sin(a[:, 0]), np.cos(a[:, 0]), np.sin(a[:, 1]), np.cos(a[:, 1]), \
        np.sin(a[:, 2]), np.cos(a[:, 2])
    return np.stack([-(L * c2 + L * s3) * s1, L * s2 - L * c3 + L, -L + (L * c2 + L * s3) * c1], axis=-1)


def test_openhaptics_angles_put_the_touch_tip_where_ubitrack_computes_it(angles):
    theta = conventions.theta_from_openhaptics(angles)
    tip = Phantom.from_model("touch").forward_kinematics(theta)[:, :3, 3]
    np.testing.assert_allclose(tip, ubitrack(angles), rtol=0, atol=1e-12)
    assert np.abs(ubitrack(angles)[:, 0]).max() > 0.05  # the sign of angle 1 matters here


def test_joint_states_of_the_drivers_give_the_openhaptics_theta(angles):
    expected = conventions.theta_from_openhaptics(angles)
    gimbal = np.random.default_rng(9).uniform(-2, 2, (len(angles), 3))
    # fsuarez6/phantom_omni: waist = -a1, shoulder = a2, elbow = a3 - a2, then the gimbal
    fsuarez6 = np.column_stack([-angles[:, 0], angles[:, 1], angles[:, 2] - angles[:, 1], gimbal])
    theta = conventions.theta_from_joint_state(["waist", "shoulder", "elbow", *GIMBAL], fsuarez6)
    np.testing.assert_allclose(theta, expected, rtol=0, atol=1e-15)
    # sawSensablePhantom: q[0] = -q[0]; q[2] -= q[1], here published in another order with a prefix
    saw = angles.copy()
    saw[:, 0] = -saw[:, 0]
    saw[:, 2] -= saw[:, 1]
    names = ["arm/roll", "arm/elbow", "arm/waist", "arm/shoulder"]
    published = np.column_stack([gimbal[:, 2], saw[:, 2], saw[:, 0], saw[:, 1]])
    theta = conventions.theta_from_joint_state(names, published, prefix="arm/")
    np.testing.assert_allclose(theta, expected, rtol=0, atol=1e-15)
    one = conventions.theta_from_joint_state(names, published[0], prefix="arm/")
    np.testing.assert_allclose(one, expected[0], rtol=0, atol=1e-15)


def test_the_conversions_invert_each_other(angles):
    theta = conventions.theta_from_openhaptics(angles)
    np.testing.assert_array_equal(conventions.openhaptics_from_theta(theta), angles)
    names, position = conventions.joint_state_from_theta(theta, prefix="omni_")
    assert names == ["omni_waist", "omni_shoulder", "omni_elbow"]
    np.testing.assert_allclose(conventions.theta_from_joint_state(names, position, "omni_"), theta, rtol=0, atol=1e-15)
    tau = np.random.default_rng(10).normal(0, 0.2, (len(angles), 3))
    np.testing.assert_allclose(conventions.tau_from_openhaptics_torque(conventions.openhaptics_torque_from_tau(tau)),
                               tau, rtol=1e-15, atol=0)


def test_openhaptics_torques_do_the_same_work_and_its_spring_restores_theta(angles):
    """Power tau . dtheta (W) equals T . da / 1000 (mN m x rad/s); the SDK sample's spring
    T = k (0 - a) (k = 1000 mN m/rad) is -1 N m/rad x theta on the report's theta."""
    rng = np.random.default_rng(11)
    rate = rng.normal(0, 1, angles.shape)                  # rad/s of the OpenHaptics angles
    torque = rng.normal(0, 300, angles.shape)              # mN m
    dtheta = conventions.theta_from_openhaptics(rate)          # the map is linear: rates as angles
    tau = conventions.tau_from_openhaptics_torque(torque)
    np.testing.assert_allclose((tau * dtheta).sum(axis=1), (torque * rate).sum(axis=1) / 1000, rtol=1e-12)
    spring = conventions.tau_from_openhaptics_torque(1000.0 * (0 - angles))
    np.testing.assert_allclose(spring, -1.0 * conventions.theta_from_openhaptics(angles), rtol=1e-15)


def test_gravity_goes_to_openhaptics_in_mN_m():
    """The torque that holds the Touch still, as OpenHaptics commands it: joint 1 carries no
    gravity; joints 2 and 3 keep their sign and are 1000 times the N m."""
    phantom = Phantom.from_model("touch")
    theta = np.array([0.4, 0.7, 0.9])
    command = conventions.openhaptics_torque_from_tau(phantom.gravity(theta))
    np.testing.assert_allclose(command[1:], 1000 * phantom.gravity(theta)[1:], rtol=1e-15)
    assert command[0] == pytest.approx(0, abs=1e-12)


@pytest.mark.parametrize("names, position, argument", [
    (["waist", "shoulder"], [0.1, 0.2], "names"),
    (["waist", "shoulder", "elbow", "elbow"], [0, 0, 0, 0], "names"),
    ("waist shoulder elbow", [0, 0, 0], "names"),
    ([1, 2, 3], [0, 0, 0], "names"),
    (["waist", "shoulder", "elbow"], [0.1, 0.2], "position"),
    (["waist", "shoulder", "elbow"], [0.1, np.nan, 0.3], "position"),
    (["waist", "shoulder", "elbow"], ["a", "b", "c"], "position"),
])
def test_bad_joint_states_raise_naming_the_argument(names, position, argument):
    with pytest.raises(InvalidInputError, match=f"^{argument}: "):
        conventions.theta_from_joint_state(names, position)


@pytest.mark.parametrize("function", [conventions.theta_from_openhaptics, conventions.openhaptics_from_theta,
                                      conventions.tau_from_openhaptics_torque, conventions.openhaptics_torque_from_tau])
def test_bad_vectors_raise_naming_the_argument(function):
    with pytest.raises(InvalidInputError, match=r"^(angles|theta|torque|tau): "):
        function([1.0, 2.0])


@pytest.mark.parametrize("call, argument", [
    (lambda: conventions.openhaptics_torque_from_tau([1e306, 0.0, 0.0]), "tau"),
    (lambda: conventions.theta_from_joint_state(["waist", "shoulder", "elbow"], [0.0, 1e308, 1e308]), "position"),
    (lambda: conventions.joint_state_from_theta([0.0, -1e308, 1e308]), "theta"),
    (lambda: conventions.joint_state_from_theta([0.0, 0.0, 0.0], prefix=5), "prefix"),
    (lambda: conventions.theta_from_joint_state(["waist", "shoulder", "elbow"], [0.0, 0.0, 0.0], prefix=None),
     "prefix"),
])
def test_overflow_and_a_non_string_prefix_are_named_errors(call, argument):
    """Before: -inf or inf came back from a finite input (1000 x 1e306 N m; 1e308 + 1e308 rad),
    and a prefix of 5 raised TypeError."""
    with pytest.raises(InvalidInputError) as error:
        call()
    assert error.value.argument == argument


# -- HD_CURRENT_TRANSFORM: a finite rigid pose, column-major; the gimbal's joint states ---------


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


@pytest.mark.parametrize("pose", [
    "abc",                                                          # a string
    transform(1.1 * ROTATION, [10, 20, 30]) * [[1], [1], [1], [1]],  # scaled
    transform(ROTATION, [1e308, 0, 0]) / 1000,                      # 1e305 m: its mm overflow
    transform(ROTATION @ np.diag([-1.0, 1, 1]), [0, 0, 0]),         # a mirror (det -1)
    [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0]],                     # 3x4
])
def test_openhaptics_transform_from_pose_refuses_what_is_not_a_finite_rigid_pose(pose):
    """openhaptics_transform_from_pose takes a finite rigid pose only: a string, a scaled or
    mirrored rotation, a translation whose mm overflow and a 3x4 matrix are each refused with
    InvalidInputError naming ``pose``."""
    with pytest.raises(InvalidInputError) as error:
        conventions.openhaptics_transform_from_pose(pose)
    assert error.value.argument == "pose"


def test_a_mirrored_hd_current_transform_is_refused():
    """An HD_CURRENT_TRANSFORM whose rotation is mirrored (orthogonal of determinant -1, which
    R R^T = I alone lets through) is refused naming ``transform``."""
    for mirror in (np.diag([-1.0, 1, 1]), -np.eye(3)):
        rotation = ROTATION @ mirror
        assert np.allclose(rotation @ rotation.T, np.eye(3), atol=1e-12) and np.linalg.det(rotation) < 0
        flat = transform(rotation, [12.0, -70.0, -50.0]).T.ravel()   # column-major
        with pytest.raises(InvalidInputError) as error:
            conventions.pose_from_openhaptics_transform(flat)
        assert error.value.argument == "transform"


def test_a_row_major_hd_current_transform_is_refused():
    """An HD_CURRENT_TRANSFORM is read column-major, OpenHaptics' order (the translation at
    12..14): a row-major one (its translation read as the last row, its rotation transposed,
    still proper) is refused by its last row, naming ``transform``; column-major, the same numbers
    give the pose in m."""
    matrix = transform(ROTATION, [12.0, -70.0, -50.0])
    with pytest.raises(InvalidInputError) as error:
        conventions.pose_from_openhaptics_transform(matrix.ravel())        # row-major
    assert error.value.argument == "transform"
    flat = matrix.T.ravel()
    assert np.array_equal(flat[12:15], [12.0, -70.0, -50.0])
    assert np.abs(conventions.pose_from_openhaptics_transform(flat)[:3, :3] - ROTATION).max() < 1e-15


def test_omni_firewire_gimbal_rates_convert_without_the_offsets():
    """omni_firewire's gimbal rates convert without the angles' offsets. fsuarez6/phantom_omni
    omni_state.cpp 188-193 publishes yaw = pi - g1, pitch = -g2 - 3 pi / 4, roll = -g3 - pi,
    written out here: the rates of a motion g(t) are the finite difference of those positions
    (the map is affine: exact up to rounding, 1e-6 rad/s)."""
    rng = np.random.default_rng(42)
    g0, rate, h = rng.uniform(-0.5, 0.5, 3), rng.uniform(-2, 2, 3), 1e-3

    def published(g):
        return np.array([math.pi - g[0], -g[1] - 3 * math.pi / 4, -g[2] - math.pi])

    published_rate = (published(g0 + rate * h) - published(g0)) / h
    names = ["roll", "yaw", "pitch"]
    order = [2, 0, 1]
    back = conventions.gimbal_from_joint_state(names, published_rate[order], convention="omni_firewire", rates=True)
    assert np.abs(back - rate).max() < 1e-6
    positions = conventions.gimbal_from_joint_state(names, published(g0)[order], convention="omni_firewire")
    assert np.abs(positions - g0).max() < 1e-14


def test_gimbal_joint_states_with_a_prefix_read_their_own_names():
    """With a prefix, the gimbal's joint states are read under the prefixed names only (two
    devices in one message, unprefixed and left_: each prefix reads its own three values; raw
    convention: the values themselves), the names written carry it, and a message without them
    is refused naming ``names``."""
    names = ["left_roll", "yaw", "left_yaw", "pitch", "left_pitch", "roll"]
    values = [0.3, -1.0, 0.1, -2.0, 0.2, -3.0]
    assert np.array_equal(conventions.gimbal_from_joint_state(names, values, prefix="left_"), [0.1, 0.2, 0.3])
    assert np.array_equal(conventions.gimbal_from_joint_state(names, values), [-1.0, -2.0, -3.0])
    written, position = conventions.joint_state_from_gimbal([0.1, 0.2, 0.3], prefix="left_")
    assert written == ["left_yaw", "left_pitch", "left_roll"] and np.array_equal(position, [0.1, 0.2, 0.3])
    with pytest.raises(InvalidInputError) as error:
        conventions.gimbal_from_joint_state(["yaw", "pitch", "roll"], [0, 0, 0], prefix="left_")
    assert error.value.argument == "names"


# -- OpenHaptics' origin: frame s's origin in OpenHaptics' coordinates ------------------------------

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
    """HD_CURRENT_TRANSFORM's translation is taken from OpenHaptics' origin, frame s's origin in
    its coordinates from gimbal.yaml's openhaptics_shoulder (Carrot404's base_ref, an estimate),
    not as frame s's: with it every point of a real Touch's logged box (a 3x3x3 grid, its corners
    included; the translation of an HD_CURRENT_TRANSFORM is the gimbal centre, the stylus frame's
    origin) maps to a gimbal-centre position that the report's inverse kinematics reaches inside
    the stops; with the origins equal none does (it needs theta2 < 0; the Touch's stop is 0)."""
    report = read("touch").report
    for point in logged_box():
        flat = np.eye(4)
        flat[:3, 3] = point
        flat = flat.T.ravel()                                 # column-major, mm
        estimated = conventions.pose_from_openhaptics_transform(flat)[:3, 3]
        assert reachable_inside_the_stops(estimated, report), point
        equal = conventions.pose_from_openhaptics_transform(flat, origin=np.zeros(3))[:3, 3]
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
    assert np.abs(conventions.openhaptics_origin() - (np.array(stated) - shoulder)).max() < 1e-15
    assert np.array_equal(conventions.openhaptics_origin(Phantom.from_model("touch")), conventions.openhaptics_origin())
    moved = describe("touch", overrides={"openhaptics_shoulder.2": -0.2})
    assert np.abs(conventions.openhaptics_origin(moved) - conventions.openhaptics_origin() - [0, 0, -0.2 - stated[2]]
                  ).max() < 1e-15
    back = conventions.pose_from_openhaptics_transform(conventions.openhaptics_transform_from_pose(
        transform(ROTATION, [0.01, 0.02, 0.03]) / [[1], [1], [1], [1]], origin=conventions.openhaptics_origin(moved)),
        origin=conventions.openhaptics_origin(moved))
    assert np.abs(back[:3, 3] - [0.01, 0.02, 0.03]).max() < 1e-15
    with pytest.raises(ParameterFileError, match="openhaptics_shoulder"):
        describe("touch", overrides={"openhaptics_shoulder.2": -157})
    with pytest.raises(InvalidInputError) as error:
        conventions.openhaptics_origin(Phantom.from_model("premium_1_5"))
    assert error.value.argument == "phantom"
    with pytest.raises(InvalidInputError) as error:
        conventions.pose_from_openhaptics_transform(np.eye(4).ravel(), origin=[[0, 0, 0]])
    assert error.value.argument == "origin"


# -- one reader of joint_states per driver (conventions.JointConvention) ---------------------------------
WAIST_NAMED = ("geomagic_touch_ros2", "sawsensablephantom", "phantom_touch_ros2", "touch_ros2_control")


def _waist_sign(name: str) -> float:
    """a1's coefficient in the waist each driver publishes (driver_reference.published, its source lines)."""
    return driver_reference.published(name, np.array([1.0, 0.0, 0.0]), np.zeros(3))[1][0]


@pytest.mark.parametrize("name", profiles.names())
def test_each_profiles_convention_reads_its_drivers_published_angles_back(name):
    """The profile's JointConvention, batched, on the driver's own formulas of 200 seeded
    OpenHaptics angles inside the stops: theta = (-a1, a2, a3) and g raw, 1e-15 rad (one sum
    a3 - a2 + a2 rounds); the inverse gives the driver's numbers back, 1e-15 rad."""
    convention = profiles.load(name).joint_states.convention
    theta, g = driver_reference.states(200, seed=21)
    a = theta * [-1.0, 1.0, 1.0]
    published = np.array([driver_reference.published(name, x, y)[1] for x, y in zip(a, g)])
    np.testing.assert_allclose(convention.theta(published[:, :3]), theta, rtol=0, atol=1e-15)
    np.testing.assert_allclose(convention.gimbal(published[:, 3:]), g, rtol=0, atol=1e-15)
    np.testing.assert_allclose(convention.published(theta), published[:, :3], rtol=0, atol=1e-15)
    np.testing.assert_allclose(convention.published_gimbal(g), published[:, 3:], rtol=0, atol=1e-15)


def test_the_waist_signs_found_at_the_drivers_sources():
    """-a1 (= theta1) in the fsuarez6 lineage and sawSensablePhantom, +a1 (= -theta1) in kinisi's,
    CalaW's and RViMLab's drivers (driver_reference.published's source lines); the fixed
    convention, the plain node's and the driver URDF's, is the older drivers': sawSensablePhantom's
    profile exactly."""
    assert {name: _waist_sign(name) for name in profiles.names()} == {
        "geomagic_touch_ros2": -1.0, "sawsensablephantom": -1.0, "phantom_touch_ros2": 1.0,
        "touch_ros2_control": 1.0, "geomagic_touch_x_ros2": 1.0}
    assert profiles.load("sawsensablephantom").joint_states.convention == conventions.FIXED_CONVENTION
    assert conventions.FIXED_CONVENTION.arm_signs[0] == _waist_sign("sawsensablephantom")


@pytest.mark.parametrize("name", WAIST_NAMED)
def test_the_plain_node_puts_the_tip_where_ubitrack_does_for_the_older_drivers_and_mirrored_for_the_others(name):
    """ros2.Bridge (no --driver) on each driver's own joint_states, arm names only: its tip in
    base_link (REP-103 axes, origin at the shoulder) is Ubitrack's position of the OpenHaptics
    angles, 1e-12 m,
    for the drivers whose waist is -a1; for kinisi's and CalaW's (+a1) it is that position
    mirrored about joint 1's plane (x of frame s negated), the mirror the docs warn of, while
    their profiles (DriverBridge, theta_from_joint_state with the profile's convention) read
    theta right."""
    from phantom_pin.interfaces.ros2.node import Bridge, DriverBridge

    touch = Phantom.from_model("touch")
    plain, profile = Bridge(touch), profiles.load(name)
    mirror = np.diag([_waist_sign(name) * -1.0, 1.0, 1.0])   # identity where the waist is -a1
    theta, g = driver_reference.states(20, seed=22)
    for t, gg in zip(theta, g):
        a = t * [-1.0, 1.0, 1.0]
        names, positions = driver_reference.published(name, a, gg)
        tip = plain(names[:3], positions[:3]).tip[:3, 3]
        position = ubitrack(np.array([a]))[0]   # frame s, whose origin is (0, l2, -l1) from the shoulder's
        expected = driver_reference.BASE_FROM_S @ (mirror @ position - [0.0, driver_reference.L2, -driver_reference.L1])
        np.testing.assert_allclose(tip, expected, rtol=0, atol=1e-12)
        theta_read = conventions.theta_from_joint_state(names, positions, convention=profile.joint_states.convention)
        np.testing.assert_allclose(theta_read, t, rtol=0, atol=1e-15)
        np.testing.assert_allclose(DriverBridge(touch, profile).state(names, positions)[0], t, rtol=0, atol=1e-15)
    assert np.abs(position[0]) > 1e-3   # x matters: the mirror is seen


@pytest.mark.parametrize("arguments, argument", [
    (((-1.0, 2.0, 1.0), "relative"), "arm_signs"),
    (((-1.0, 1.0, 1.0), "relativ"), "elbow"),
    (((-1.0, 1.0, 1.0), "relative", (1.0, 1.0, 0.0)), "gimbal_signs"),
    (((-1.0, 1.0, 1.0), "relative", (1.0, 1.0, 1.0), (0.0, float("nan"), 0.0)), "gimbal_offsets"),
    (((True, 1.0, 1.0), "relative"), "arm_signs"),
])
def test_a_bad_joint_convention_is_refused_naming_its_field(arguments, argument):
    with pytest.raises(InvalidInputError) as error:
        conventions.JointConvention(*arguments)
    assert isinstance(error.value, ValueError) and error.value.argument == argument
    with pytest.raises(InvalidInputError) as error:
        conventions.theta_from_joint_state(["waist", "shoulder", "elbow"], [0.0, 0.0, 0.0], convention="kinisi")
    assert error.value.argument == "convention"


def test_the_origin_puts_the_shoulder_where_the_arm_turns_about_it_with_unequal_links():
    """Mutant 31. A Touch whose links differ (l1 = 0.20 m, l2 = 0.11 m; the Touch's equal links
    hide a swap): frame s's origin in OpenHaptics' coordinates is openhaptics_shoulder less the
    shoulder in frame s, and the shoulder is the point whose distance to the gimbal centre
    depends on the elbow's angle alone, |p - S|^2 = l1^2 + l2^2 + 2 l1 l2 sin(theta3 - theta2)
    (the law of cosines), p Ubitrack's position formula with those lengths (the gimbal centre in
    frame s, PhantomForwardKinematics.h lines 101-103): 1e-12 m^2 over 50 seeded postures."""
    import dataclasses

    config = read("touch")
    l1, l2 = 0.20, 0.11
    config = dataclasses.replace(config, kinematics=dataclasses.replace(config.kinematics, l1=l1, l2=l2))
    shoulder = np.array(config.gimbal.openhaptics_shoulder) - conventions.openhaptics_origin(config)   # frame s
    theta = sample_postures(config.limits, 50, np.random.default_rng(23), draws=200)
    a = theta * [-1.0, 1.0, 1.0]                        # OpenHaptics' angles (Ubitrack's)
    s1, c1, s2, c2, s3, c3 = np.sin(a[:, 0]), np.cos(a[:, 0]), np.sin(a[:, 1]), np.cos(a[:, 1]), \
        np.sin(a[:, 2]), np.cos(a[:, 2])
    p = np.stack([-(l1 * c2 + l2 * s3) * s1, l1 * s2 - l2 * c3 + l2, -l1 + (l1 * c2 + l2 * s3) * c1], axis=-1)
    distance = ((p - shoulder) ** 2).sum(axis=1)
    np.testing.assert_allclose(distance, l1**2 + l2**2 + 2 * l1 * l2 * np.sin(theta[:, 2] - theta[:, 1]),
                               rtol=0, atol=1e-12)
