"""phantom_pin.drivers against the drivers' own published formulas, written out here:

- Ubitrack's forward kinematics of OpenHaptics' joint angles (Ubitrack/component_haptic_calibration,
  src/utHaptics/Function/PhantomForwardKinematics.h lines 101-103, without calibration offsets),
  against Phantom.from_model("touch")'s tip in the report's frame s;
- the ROS joint_states of fsuarez6/phantom_omni (omni_state.cpp: waist = -a1, shoulder = a2,
  elbow = a3 - a2) and of jhu-saw/sawSensablePhantom (mtsSensableHD.cpp: q[0] = -q[0]; q[2] -= q[1]);
- SensAble's CommandJointTorque sample: torque (mN m) = k (0 - angle) is a restoring spring;
- and power: the same motion does the same work in either convention.
"""

import numpy as np
import pytest

from phantom_pin import Phantom, drivers
from phantom_pin.config import read
from phantom_pin.config.sampling import sample_postures
from phantom_pin.exceptions import InvalidInputError

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
    theta = drivers.theta_from_openhaptics(angles)
    tip = Phantom.from_model("touch").forward_kinematics(theta)[:, :3, 3]
    np.testing.assert_allclose(tip, ubitrack(angles), rtol=0, atol=1e-12)
    assert np.abs(ubitrack(angles)[:, 0]).max() > 0.05  # the sign of angle 1 matters here


def test_joint_states_of_the_drivers_give_the_openhaptics_theta(angles):
    expected = drivers.theta_from_openhaptics(angles)
    gimbal = np.random.default_rng(9).uniform(-2, 2, (len(angles), 3))
    # fsuarez6/phantom_omni: waist = -a1, shoulder = a2, elbow = a3 - a2, then the gimbal
    fsuarez6 = np.column_stack([-angles[:, 0], angles[:, 1], angles[:, 2] - angles[:, 1], gimbal])
    theta = drivers.theta_from_joint_state(["waist", "shoulder", "elbow", *GIMBAL], fsuarez6)
    np.testing.assert_allclose(theta, expected, rtol=0, atol=1e-15)
    # sawSensablePhantom: q[0] = -q[0]; q[2] -= q[1], here published in another order with a prefix
    saw = angles.copy()
    saw[:, 0] = -saw[:, 0]
    saw[:, 2] -= saw[:, 1]
    names = ["arm/roll", "arm/elbow", "arm/waist", "arm/shoulder"]
    published = np.column_stack([gimbal[:, 2], saw[:, 2], saw[:, 0], saw[:, 1]])
    theta = drivers.theta_from_joint_state(names, published, prefix="arm/")
    np.testing.assert_allclose(theta, expected, rtol=0, atol=1e-15)
    one = drivers.theta_from_joint_state(names, published[0], prefix="arm/")
    np.testing.assert_allclose(one, expected[0], rtol=0, atol=1e-15)


def test_the_conversions_invert_each_other(angles):
    theta = drivers.theta_from_openhaptics(angles)
    np.testing.assert_array_equal(drivers.openhaptics_from_theta(theta), angles)
    names, position = drivers.joint_state_from_theta(theta, prefix="omni_")
    assert names == ["omni_waist", "omni_shoulder", "omni_elbow"]
    np.testing.assert_allclose(drivers.theta_from_joint_state(names, position, "omni_"), theta, rtol=0, atol=1e-15)
    tau = np.random.default_rng(10).normal(0, 0.2, (len(angles), 3))
    np.testing.assert_allclose(drivers.tau_from_openhaptics_torque(drivers.openhaptics_torque_from_tau(tau)),
                               tau, rtol=1e-15, atol=0)


def test_openhaptics_torques_do_the_same_work_and_its_spring_restores_theta(angles):
    """Power tau . dtheta (W) equals T . da / 1000 (mN m x rad/s); the SDK sample's spring
    T = k (0 - a) (k = 1000 mN m/rad) is -1 N m/rad x theta on the report's theta."""
    rng = np.random.default_rng(11)
    rate = rng.normal(0, 1, angles.shape)                  # rad/s of the OpenHaptics angles
    torque = rng.normal(0, 300, angles.shape)              # mN m
    dtheta = drivers.theta_from_openhaptics(rate)          # the map is linear: rates as angles
    tau = drivers.tau_from_openhaptics_torque(torque)
    np.testing.assert_allclose((tau * dtheta).sum(axis=1), (torque * rate).sum(axis=1) / 1000, rtol=1e-12)
    spring = drivers.tau_from_openhaptics_torque(1000.0 * (0 - angles))
    np.testing.assert_allclose(spring, -1.0 * drivers.theta_from_openhaptics(angles), rtol=1e-15)


def test_gravity_goes_to_openhaptics_in_mN_m():
    """The torque that holds the Touch still, as OpenHaptics commands it: joint 1 carries no
    gravity; joints 2 and 3 keep their sign and are 1000 times the N m."""
    phantom = Phantom.from_model("touch")
    theta = np.array([0.4, 0.7, 0.9])
    command = drivers.openhaptics_torque_from_tau(phantom.gravity(theta))
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
        drivers.theta_from_joint_state(names, position)


@pytest.mark.parametrize("function", [drivers.theta_from_openhaptics, drivers.openhaptics_from_theta,
                                      drivers.tau_from_openhaptics_torque, drivers.openhaptics_torque_from_tau])
def test_bad_vectors_raise_naming_the_argument(function):
    with pytest.raises(InvalidInputError, match=r"^(angles|theta|torque|tau): "):
        function([1.0, 2.0])


@pytest.mark.parametrize("call, argument", [
    (lambda: drivers.openhaptics_torque_from_tau([1e306, 0.0, 0.0]), "tau"),
    (lambda: drivers.theta_from_joint_state(["waist", "shoulder", "elbow"], [0.0, 1e308, 1e308]), "position"),
    (lambda: drivers.joint_state_from_theta([0.0, -1e308, 1e308]), "theta"),
    (lambda: drivers.joint_state_from_theta([0.0, 0.0, 0.0], prefix=5), "prefix"),
    (lambda: drivers.theta_from_joint_state(["waist", "shoulder", "elbow"], [0.0, 0.0, 0.0], prefix=None), "prefix"),
])
def test_overflow_and_a_non_string_prefix_are_named_errors(call, argument):
    """Before: -inf or inf came back from a finite input (1000 x 1e306 N m; 1e308 + 1e308 rad),
    and a prefix of 5 raised TypeError."""
    with pytest.raises(InvalidInputError) as error:
        call()
    assert error.value.argument == argument
