"""The angles and torques of the PHANToM drivers, to and from the report's theta.

Every PHANToM driver reads OpenHaptics (HD_CURRENT_JOINT_ANGLES, rad) and publishes its own
convention; phantom_pin computes in the report's theta (rad) and joint torques (N m). These
maps let a user feed an OpenHaptics log or ROS ``joint_states`` straight into
Phantom.forward_kinematics, Phantom.gravity, simulate and identify, and send the results back.

OpenHaptics (``openhaptics_*``), sources:

- angles: Ubitrack/component_haptic_calibration (commit bf778bb),
  src/utHaptics/Function/PhantomForwardKinematics.h lines 101-103, computes the tip in
  OpenHaptics' frame from HD_CURRENT_JOINT_ANGLES as x = -(l1 c2 + l2 s3) s1,
  y = l1 s2 - l2 c3 + l2, z = -l1 + (l1 c2 + l2 s3) c1: the report's eq. 10, in the report's
  frame s (OpenHaptics' axes: x to the user's right, y up, z towards the user), with the
  sign of theta1 reversed and theta3 absolute, as the report's. So
  theta = (-angle1, angle2, angle3).
- torques: HD_CURRENT_JOINT_TORQUE is in mN m (the comments of SensAble's CommandJointTorque
  sample, "T: Torque in Milli Newton . meter"), each acting on its own OpenHaptics angle:
  that sample renders a restoring spring with torque = k (0 - angle), k > 0. The sign is
  inferred from that sample, not stated by any public document: check it on your device
  (docs/touch.md). So tau (N m) = (-torque1, torque2, torque3) / 1000.

ROS ``joint_states`` (``joint_state_*``): the drivers publish waist = -angle1 = theta1,
shoulder = angle2 = theta2, elbow = angle3 - angle2 = theta3 - theta2 (fsuarez6/phantom_omni
omni_common/src/omni_state.cpp lines 182-193 and 296-300; jhu-saw/sawSensablePhantom
core/components/code/mtsSensableHD.cpp lines 417-419, ``q[0] = -q[0]; q[2] -= q[1]``;
bgromov/sensable_phantom src/phantom_node.cpp lines 319-320), names optionally prefixed
(their gimbal joints yaw, pitch, roll are not the report's and are ignored). The map is linear,
so joint velocities convert as positions do. The drivers' efforts follow no common rule
(sawSensablePhantom publishes OpenHaptics' raw joint torques): convert those with
``openhaptics_torque_to_tau``.

Arrays: one vector (3,) or a batch (N, 3), as the rest of phantom_pin.
"""

from __future__ import annotations

import numpy as np

from phantom_pin.exceptions import InvalidInputError
from phantom_pin.validation import as_states, finite_result

#: The names of the drivers' joint_states for theta1..theta3 (without prefix).
JOINT_STATE_NAMES = ("waist", "shoulder", "elbow")
#: OpenHaptics' angle i = SIGN[i] * theta_i; its joint torque (mN m) = SIGN[i] * tau_i * 1000.
_SIGN = np.array([-1.0, 1.0, 1.0])
#: mN m per N m (HD_CURRENT_JOINT_TORQUE's unit).
MILLI = 1000.0


def theta_from_openhaptics(angles: object) -> np.ndarray:
    """The report's theta (rad) of OpenHaptics' HD_CURRENT_JOINT_ANGLES (rad): (-a1, a2, a3)."""
    a, _ = as_states(angles, "angles")
    return a * _SIGN


def openhaptics_from_theta(theta: object) -> np.ndarray:
    """OpenHaptics' HD_CURRENT_JOINT_ANGLES (rad) of the report's theta (rad): (-t1, t2, t3)."""
    t, _ = as_states(theta, "theta")
    return t * _SIGN


def tau_from_openhaptics_torque(torque: object) -> np.ndarray:
    """Joint torques (N m, on the report's theta) of OpenHaptics joint torques (mN m, on its
    angles; HD_CURRENT_JOINT_TORQUE or HD_LAST_JOINT_TORQUE): (-T1, T2, T3) / 1000."""
    t, _ = as_states(torque, "torque")
    return t * _SIGN / MILLI


def openhaptics_torque_from_tau(tau: object) -> np.ndarray:
    """OpenHaptics joint torques (mN m, for HD_CURRENT_JOINT_TORQUE) of joint torques tau
    (N m on the report's theta, e.g. Phantom.gravity): 1000 (-tau1, tau2, tau3)."""
    t, _ = as_states(tau, "tau")
    with np.errstate(over="ignore"):  # reported by finite_result, naming tau
        return finite_result(t * _SIGN * MILLI, "tau")


def _prefix(prefix: object) -> str:
    """``prefix`` (a ROS name prefix such as "left_") checked to be a str."""
    if not isinstance(prefix, str):
        raise InvalidInputError(f"expected a str such as '' or 'left_', got {prefix!r}", argument="prefix")
    return prefix


def theta_from_joint_state(names: object, position: object, prefix: str = "") -> np.ndarray:
    """The report's theta (rad) of a driver's joint_states: ``names`` (sequence of str, as in
    sensor_msgs/JointState, each joint of JOINT_STATE_NAMES with ``prefix`` exactly once;
    others, such as the gimbal's, are ignored) and ``position`` (rad, one value per name, or
    (N, len(names)) for a batch): theta = (waist, shoulder, shoulder + elbow). Velocities
    (rad/s) convert the same way."""
    if isinstance(names, str) or not all(isinstance(n, str) for n in np.asarray(names, dtype=object).ravel()):
        raise InvalidInputError(f"expected a sequence of joint names, got {names!r}", argument="names")
    given: list[str] = list(names)  # type: ignore[call-overload]  # checked above: an iterable of str
    wanted = [_prefix(prefix) + name for name in JOINT_STATE_NAMES]
    missing = [name for name in wanted if given.count(name) != 1]
    if missing:
        raise InvalidInputError(f"must hold each of {', '.join(wanted)} exactly once; "
                                f"{', '.join(missing)} {'is' if len(missing) == 1 else 'are'} not, in {given}",
                                argument="names")
    values, _ = as_states(position, "position", width=len(given))
    waist, shoulder, elbow = (values[..., given.index(name)] for name in wanted)
    with np.errstate(over="ignore"):  # reported by finite_result, naming position
        return finite_result(np.stack([waist, shoulder, shoulder + elbow], axis=-1), "position")


def joint_state_from_theta(theta: object, prefix: str = "") -> tuple[list[str], np.ndarray]:
    """(names, position) of the drivers' joint_states for the report's theta (rad):
    ([prefix + waist, shoulder, elbow], (theta1, theta2, theta3 - theta2)), (3,) or (N, 3)."""
    t, _ = as_states(theta, "theta")
    names = [_prefix(prefix) + name for name in JOINT_STATE_NAMES]
    with np.errstate(over="ignore"):  # reported by finite_result, naming theta
        return names, finite_result(np.stack([t[..., 0], t[..., 1], t[..., 2] - t[..., 1]], axis=-1), "theta")
