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

ROS ``joint_states`` (``joint_state_*``, JointConvention): every driver publishes OpenHaptics'
raw angles a (HD_CURRENT_JOINT_ANGLES) and g (HD_CURRENT_GIMBAL_ANGLES) through a fixed linear
(for the gimbal affine) map, its JointConvention: ``published = arm_signs * (a1, a2, a3 - a2)``
(elbow "relative") or ``arm_signs * a`` ("absolute"), gimbal ``gimbal_signs * g + offsets``. The
drivers differ in the waist's sign (read at each driver's source; docs/drivers.md has the
table):

- waist = -a1 = theta1: the older drivers, the fsuarez6/phantom_omni lineage (fsuarez6/phantom_omni
  omni_common/src/omni_state.cpp; bharatm11/Geomagic_Touch_ROS_Drivers 34e9fac omni_state.cpp
  line 183 with 236 and 296-298; its ROS 2 ports IvoD1998/Geomagic_Touch_ROS2 cd0cdba and
  stevens-armlab/Geomagic_Touch_ROS2 2e4b1f5 omni_state.cpp line 228 with 286 and 343-347),
  WPI-AIM/ros_geomagic 441542c geomagic_control/src/device_node.cpp line 200 with 260 and 301-303,
  and jhu-saw/sawSensablePhantom 7ddd575 core/components/code/mtsSensableHD.cpp lines 312-313 and
  418-419 (``q[0] = -q[0]; q[2] -= q[1]``). Their convention, FIXED_CONVENTION, is the one
  urdf/touch_driver.urdf, the ``ros2`` node without ``--driver`` and the
  ``joint_state_*`` functions here read.
- waist = +a1 = -theta1: kinisi-robotics/phantom_touch_ros2 2bf5b20
  phantom_touch_control/src/hd++.cpp lines 257-268 (no sign, ``angles[2] -= angles[1]``),
  published as they are by phantom_touch_control_node.cpp line 314; CalaW/touch_ros2_control
  e1e181e touch_hardware/src/touch_driver_node.cpp line 169 and
  touch_hardware/include/touch_hardware/device_transforms.hpp lines 77-87 (no sign); and
  RViMLab/geomagic_touch_x_ros2 57da5c9 src/device.cpp line 54, src/geomagic_touch_x_component.cpp
  lines 161 and 177 (raw, elbow absolute). Read these through their profiles
  (phantom_pin.interfaces.profiles: Profile.joint_states.convention; ``ros2 --driver``): FIXED_CONVENTION
  would mirror them about joint 1.

The gimbal's yaw, pitch, roll are OpenHaptics' raw g1..g3 (rad) in the Touch-era drivers
(GIMBAL_CONVENTIONS["raw"]: jhu-saw/sawSensablePhantom since commit 69776dd, "Removing strange
offsets on gimbal joints added to compensate for issues with old Omni"; kinisi-robotics/
phantom_touch_ros2 2bf5b20; CalaW/touch_ros2_control e1e181e), which are the model's
joint4..joint6 (Phantom.stylus_pose). The fsuarez6/phantom_omni lineage (and its forks)
publishes yaw = pi - g1, pitch = -g2 - 3 pi / 4, roll = -g3 - pi (omni_state.cpp lines 188-193),
tuned for the old FireWire Omni: GIMBAL_CONVENTIONS["omni_firewire"], a per-device convention to
choose, not the default. The maps are affine, so joint velocities convert as positions do,
without the offsets (``rates=True``). The drivers' efforts follow no common rule
(sawSensablePhantom publishes OpenHaptics' raw joint torques): convert those with
``tau_from_openhaptics_torque``.

HD_CURRENT_TRANSFORM (``pose_from_openhaptics_transform``): the 16 numbers of the stylus's
column-major 4x4 transform, translation in mm, in OpenHaptics' axes, which are frame s's. Its
origin is OpenHaptics' own, which no public source states: ``openhaptics_origin`` gives frame
s's origin (the zero posture's gimbal centre, eq. 10) in OpenHaptics' coordinates from a
model's gimbal.yaml (``openhaptics_shoulder``, the shoulder's position there; for the Touch an
ESTIMATE, +-10-20 mm: Carrot404/Touch_ROS_Drivers_Applications' touch.urdf, commit 00863fb,
base_ref, which puts the shoulder at (0, 35, -157) mm). Ubitrack's calibration model
(PhantomForwardKinematics.h above) puts OpenHaptics' origin at frame s's (its offsets zero);
a real Touch's logged HD_CURRENT_TRANSFORM positions (iLUVE69/Limb-Impedance-measurement-
using-GeoMagic-Touch-Haptic-Device) reach no posture inside the stops with that, and all of
them with the estimate (tests/interfaces/test_conventions.py). Check it on your device: the gimbal
centre's HD_CURRENT_POSITION at a known posture gives it.

Arrays: one vector (3,) or a batch (..., 3), as the rest of phantom_pin.
"""

from __future__ import annotations

import dataclasses
import functools
import math

import numpy as np

from phantom_pin._paths import PROFILES_DIR
from phantom_pin._validation import as_states, finite_result
from phantom_pin.config import Config, read
from phantom_pin.config.files import read_yaml
from phantom_pin.exceptions import InvalidInputError, ParameterFileError

#: The names of the drivers' joint_states for theta1..theta3 (without prefix).
JOINT_STATE_NAMES = ("waist", "shoulder", "elbow")
#: The names of the drivers' joint_states for the stylus gimbal (without prefix).
GIMBAL_STATE_NAMES = ("yaw", "pitch", "roll")
#: How a driver publishes the gimbal: name -> (signs, offsets (rad)), published = sign * g +
#: offset, g OpenHaptics' raw HD_CURRENT_GIMBAL_ANGLES (the module's doc gives the sources).
GIMBAL_CONVENTIONS = {
    "raw": ((1.0, 1.0, 1.0), (0.0, 0.0, 0.0)),
    "omni_firewire": ((-1.0, -1.0, -1.0), (math.pi, -3 * math.pi / 4, -math.pi)),
}
#: m per mm (HD_CURRENT_TRANSFORM's and HD_CURRENT_POSITION's unit).
METRE_PER_MM = 1e-3
#: OpenHaptics' angle i = OPENHAPTICS_SIGN[i] * theta_i; its joint torque (mN m) =
#: OPENHAPTICS_SIGN[i] * tau_i * 1000 (the module's doc gives the sources). The one statement
#: of the law: phantom_pin.interfaces.profiles reads it from here.
OPENHAPTICS_SIGN = (-1.0, 1.0, 1.0)
_SIGN = np.array(OPENHAPTICS_SIGN)
#: mN m per N m (HD_CURRENT_JOINT_TORQUE's unit).
MILLI = 1000.0


#: How a driver publishes the elbow: "relative" (a3 - a2, the Touch-era drivers) or "absolute" (a3).
ELBOWS = ("relative", "absolute")


def _signs(value: object, argument: str) -> tuple[float, float, float]:
    if (not isinstance(value, (tuple, list)) or len(value) != 3
            or not all(isinstance(v, (int, float)) and not isinstance(v, bool) and v in (-1, 1) for v in value)):
        raise InvalidInputError(f"expected three signs, each 1 or -1, got {value!r}", argument=argument)
    return float(value[0]), float(value[1]), float(value[2])


@dataclasses.dataclass(frozen=True)
class JointConvention:
    """How a driver publishes OpenHaptics' raw angles as joint_states (rad; the module's doc):
    the arm ``published = arm_signs * (a1, a2, a3 - a2)`` (``elbow`` "relative") or ``arm_signs
    * (a1, a2, a3)`` ("absolute"), the gimbal ``published = gimbal_signs * g + gimbal_offsets``.
    The one reader of every driver's joint states: each profile's (Profile.joint_states.convention)
    and FIXED_CONVENTION (urdf/touch_driver.urdf, the ``ros2`` node without a driver).
    InvalidInputError naming the field for a sign other than 1 or -1, an unknown elbow or an
    offset that is not finite. Each method takes (3,) or (..., 3) and is exact (signs, one sum)."""

    arm_signs: tuple[float, float, float]
    elbow: str = "relative"
    gimbal_signs: tuple[float, float, float] = (1.0, 1.0, 1.0)
    gimbal_offsets: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        object.__setattr__(self, "arm_signs", _signs(self.arm_signs, "arm_signs"))
        object.__setattr__(self, "gimbal_signs", _signs(self.gimbal_signs, "gimbal_signs"))
        if not isinstance(self.elbow, str) or self.elbow not in ELBOWS:
            raise InvalidInputError(f"expected one of {', '.join(ELBOWS)}, got {self.elbow!r}", argument="elbow")
        offsets, _ = as_states(self.gimbal_offsets, "gimbal_offsets")
        if offsets.shape != (3,):
            raise InvalidInputError(f"expected three offsets (rad), got {self.gimbal_offsets!r}",
                                    argument="gimbal_offsets")
        object.__setattr__(self, "gimbal_offsets", tuple(offsets.tolist()))

    def theta(self, published: object) -> np.ndarray:
        """The report's theta (rad; rad/s of rates: the map is linear) of the three published arm
        angles, (3,) or (..., 3)."""
        a = np.asarray(published, dtype=float) * self.arm_signs   # signs are +-1: their own inverse
        if self.elbow == "relative":
            a[..., 2] += a[..., 1]
        return a * _SIGN

    def published(self, theta: object) -> np.ndarray:
        """The three published arm angles (rad; or rates) of the report's theta, (3,) or (..., 3)."""
        a = np.asarray(theta, dtype=float) * _SIGN
        if self.elbow == "relative":
            a[..., 2] -= a[..., 1]
        return a * self.arm_signs

    def effort(self, tau: object) -> np.ndarray:
        """The torques (N m) conjugate to the published arm angles of the report's joint torques
        ``tau`` (N m), (3,) or (..., 3): the same power, effort . d(published) = tau . d(theta)."""
        t = np.asarray(tau, dtype=float) * _SIGN
        if self.elbow == "relative":
            t[..., 1] += t[..., 2]
        return t * self.arm_signs

    def gimbal(self, published: object, rates: bool = False) -> np.ndarray:
        """OpenHaptics' raw gimbal angles g (rad) of the three published ones; ``rates``: rad/s,
        without the offsets."""
        p = np.asarray(published, dtype=float)
        return (p if rates else p - self.gimbal_offsets) * self.gimbal_signs

    def published_gimbal(self, gimbal: object, rates: bool = False) -> np.ndarray:
        """The three published gimbal angles (rad) of OpenHaptics' raw ones; ``rates``: rad/s,
        without the offsets."""
        p = np.asarray(gimbal, dtype=float) * self.gimbal_signs
        return p if rates else p + self.gimbal_offsets


def _three(values: object, where: str) -> tuple[float, float, float]:
    if not isinstance(values, list) or len(values) != 3 or not all(
            isinstance(v, (int, float)) and math.isfinite(v) for v in values):
        raise ParameterFileError(f"{where}: expected three finite numbers, got {values!r}")
    return float(values[0]), float(values[1]), float(values[2])


def convention_of(node: dict, where: str) -> JointConvention:
    """The JointConvention of a driver profile's ``joint_states`` node (config/drivers/NAME.yaml:
    ``arm: {signs, elbow}``, ``gimbal: {signs, offsets}``); ParameterFileError naming ``where``."""
    arm, gimbal = node["arm"], node["gimbal"]
    if arm.get("elbow") not in ELBOWS:
        raise ParameterFileError(f"{where}.arm.elbow: expected relative or absolute, got {arm.get('elbow')!r}")
    signs = _three(arm["signs"], f"{where}.arm.signs") + _three(gimbal["signs"], f"{where}.gimbal.signs")
    if any(s not in (-1.0, 1.0) for s in signs):
        raise ParameterFileError(f"{where}: every sign must be 1 or -1, got {signs}")
    offsets = _three(gimbal["offsets"], f"{where}.gimbal.offsets")
    return JointConvention(signs[:3], arm["elbow"], signs[3:], offsets)


#: The profile of the older drivers' fixed convention (the module's doc): sawSensablePhantom's,
#: waist = -a1 = theta1, shoulder = a2, elbow = a3 - a2, the gimbal raw (the fsuarez6 lineage
#: shares the arm; its gimbal is GIMBAL_CONVENTIONS["omni_firewire"]).
FIXED_PROFILE = "sawsensablephantom"
#: That profile's joint-state convention, read from config/drivers/FIXED_PROFILE.yaml: the one
#: urdf/touch_driver.urdf is jointed in, and the ``ros2`` node's without a driver.
FIXED_CONVENTION = convention_of(read_yaml(PROFILES_DIR / f"{FIXED_PROFILE}.yaml")["joint_states"],
                                 f"{FIXED_PROFILE}.yaml: joint_states")


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


def _names(names: object, wanted: list[str]) -> list[str]:
    """``names`` checked to be a sequence of str holding each of ``wanted`` exactly once."""
    if isinstance(names, str) or not all(isinstance(n, str) for n in np.asarray(names, dtype=object).ravel()):
        raise InvalidInputError(f"expected a sequence of joint names, got {names!r}", argument="names")
    given: list[str] = list(names)  # type: ignore[call-overload]  # checked above: an iterable of str
    missing = [name for name in wanted if given.count(name) != 1]
    if missing:
        raise InvalidInputError(f"must hold each of {', '.join(wanted)} exactly once; "
                                f"{', '.join(missing)} {'is' if len(missing) == 1 else 'are'} not, in {given}",
                                argument="names")
    return given


def _convention(convention: object) -> JointConvention:
    """FIXED_CONVENTION's arm with the gimbal of GIMBAL_CONVENTIONS[``convention``]."""
    if not isinstance(convention, str) or convention not in GIMBAL_CONVENTIONS:
        raise InvalidInputError(f"expected one of {', '.join(GIMBAL_CONVENTIONS)}, got {convention!r}",
                                argument="convention")
    return dataclasses.replace(FIXED_CONVENTION, gimbal_signs=GIMBAL_CONVENTIONS[convention][0],
                               gimbal_offsets=GIMBAL_CONVENTIONS[convention][1])


def gimbal_from_joint_state(names: object, position: object, prefix: str = "", convention: str = "raw",
                            rates: bool = False) -> np.ndarray:
    """OpenHaptics' raw gimbal angles g1..g3 (rad; the model's joint4..joint6) of a driver's
    joint_states: ``names`` holding each of GIMBAL_STATE_NAMES with ``prefix`` once, ``position``
    (rad) as theta_from_joint_state's; ``convention``: GIMBAL_CONVENTIONS' name of the driver's
    (default "raw", the Touch-era drivers'). ``rates``: convert velocities (rad/s), without
    the offsets."""
    reader = _convention(convention)
    given = _names(names, [_prefix(prefix) + name for name in GIMBAL_STATE_NAMES])
    values, _ = as_states(position, "position", width=len(given))
    published = np.stack([values[..., given.index(prefix + name)] for name in GIMBAL_STATE_NAMES], axis=-1)
    with np.errstate(over="ignore", invalid="ignore"):  # reported by finite_result, naming position
        return finite_result(reader.gimbal(published, rates), "position")


def joint_state_from_gimbal(gimbal: object, prefix: str = "", convention: str = "raw",
                            rates: bool = False) -> tuple[list[str], np.ndarray]:
    """(names, position) of the drivers' gimbal joint_states (GIMBAL_STATE_NAMES with
    ``prefix``) for OpenHaptics' raw gimbal angles ``gimbal`` (rad), (3,) or (..., 3), in the
    driver's ``convention``; ``rates``: velocities (rad/s), without the offsets."""
    reader = _convention(convention)
    g, _ = as_states(gimbal, "gimbal")
    names = [_prefix(prefix) + name for name in GIMBAL_STATE_NAMES]
    with np.errstate(over="ignore", invalid="ignore"):
        return names, finite_result(reader.published_gimbal(g, rates), "gimbal")


def _rigid(pose: np.ndarray, argument: str) -> None:
    """InvalidInputError naming ``argument`` unless every (4, 4) of ``pose`` is a rigid transform:
    a proper rotation (R R^T = I and det R = 1, to 1e-6: a mirror has det -1) and a last row of
    0 0 0 1 (a row-major transform read column-major has its translation there)."""
    rotation = pose[..., :3, :3]
    if (not np.allclose(rotation @ np.swapaxes(rotation, -1, -2), np.eye(3), atol=1e-6)
            or not np.allclose(np.linalg.det(rotation), 1.0, atol=1e-6)
            or not np.allclose(pose[..., 3, :], [0, 0, 0, 1], atol=1e-12)):
        raise InvalidInputError("is not a rigid transform (a proper rotation and a translation, column-major, "
                                "last row 0 0 0 1)", argument=argument)


def openhaptics_origin(phantom: object = None) -> np.ndarray:
    """Frame s's origin (the zero posture's gimbal centre) in OpenHaptics' coordinates (m),
    (3,): ``openhaptics_shoulder`` of the model's gimbal.yaml less the shoulder's position in
    frame s, (0, l2, -l1). ``phantom``: a Phantom of a model with a gimbal (or anything carrying
    its Config as ``.config``, a Description; or the Config itself); None: the shipped Touch's (an
    ESTIMATE: the module's doc). InvalidInputError naming ``phantom`` for a model without a
    gimbal.yaml."""
    if phantom is None:
        return _touch_origin().copy()
    config = getattr(phantom, "config", phantom)
    if not isinstance(config, Config) or config.gimbal is None:
        raise InvalidInputError(f"expected the Phantom (or Config) of a model with a stylus gimbal (gimbal.yaml, "
                                f"whose openhaptics_shoulder places OpenHaptics' origin), got {phantom!r}",
                                argument="phantom")
    k = config.kinematics
    return np.array(config.gimbal.openhaptics_shoulder) - [0.0, k.l2, -k.l1]


@functools.cache
def _touch_origin() -> np.ndarray:
    return openhaptics_origin(read("touch"))


def _origin(origin: object) -> np.ndarray:
    """``origin`` (m, (3,)) checked; None: the shipped Touch's (openhaptics_origin())."""
    if origin is None:
        return _touch_origin()
    value, batch = as_states(origin, "origin")
    if batch:
        raise InvalidInputError(f"expected one point (3,), got shape {value.shape}", argument="origin")
    return value


def pose_from_openhaptics_transform(transform: object, origin: object = None) -> np.ndarray:
    """The stylus's pose (4, 4) in frame s (m) of OpenHaptics' HD_CURRENT_TRANSFORM: 16 numbers,
    column-major, translation in mm (or (N, 16) for a batch); its rotation must be proper (a
    rotation to 1e-6), else InvalidInputError naming ``transform``. ``origin``: frame s's origin
    in OpenHaptics' coordinates (m, (3,)), subtracted from the translation; None: the shipped
    Touch's ESTIMATE (openhaptics_origin(); for another configuration pass
    openhaptics_origin(phantom))."""
    flat, _ = as_states(transform, "transform", width=16)
    offset = _origin(origin)
    pose = np.swapaxes(flat.reshape(flat.shape[:-1] + (4, 4)), -1, -2).copy()
    _rigid(pose, "transform")
    pose[..., :3, 3] = pose[..., :3, 3] * METRE_PER_MM - offset
    return pose


def openhaptics_transform_from_pose(pose: object, origin: object = None) -> np.ndarray:
    """HD_CURRENT_TRANSFORM's 16 numbers (column-major, mm) of a pose (4, 4) in frame s (m),
    e.g. Phantom.stylus_pose's; (N, 16) of (N, 4, 4); ``origin`` as pose_from_openhaptics_transform's,
    added to the translation. InvalidInputError naming ``pose`` for anything but finite rigid
    transforms (as pose_from_openhaptics_transform's), or a translation whose mm overflow."""
    offset = _origin(origin)
    try:
        p = np.array(pose, dtype=float)
    except (TypeError, ValueError):
        raise InvalidInputError(f"expected finite 4x4 poses, got {pose!r}", argument="pose") from None
    if p.ndim < 2 or p.shape[-2:] != (4, 4) or not np.isfinite(p).all():
        raise InvalidInputError(f"expected finite 4x4 poses, got shape {p.shape}", argument="pose")
    _rigid(p, "pose")
    with np.errstate(over="ignore", invalid="ignore"):  # reported by finite_result, naming pose
        return finite_result(transform_of_rigid(p, offset), "pose")


def transform_of_rigid(pose: np.ndarray, offset: np.ndarray) -> np.ndarray:
    """openhaptics_transform_from_pose's map without its checks, for a pose known to be a finite
    rigid transform (a model's own, in a servo loop): (..., 16), a new array."""
    p = np.array(pose, dtype=float)
    p[..., :3, 3] = (p[..., :3, 3] + offset) / METRE_PER_MM
    return np.swapaxes(p, -1, -2).reshape(p.shape[:-2] + (16,))


def _reader(convention: object) -> JointConvention:
    if not isinstance(convention, JointConvention):
        raise InvalidInputError(f"expected a phantom_pin.interfaces.conventions.JointConvention (FIXED_CONVENTION, "
                                f"or a profile's joint_states.convention), got {convention!r}", argument="convention")
    return convention


def theta_from_driver(waist: float | np.ndarray, shoulder: float | np.ndarray,
                      elbow: float | np.ndarray) -> np.ndarray:
    """The report's theta (rad) of the older drivers' coordinates (FIXED_CONVENTION; rad, floats
    or arrays of one shape; the elbow relative to the shoulder): (waist, shoulder, shoulder +
    elbow), unchecked (theta_from_joint_state checks and names its input)."""
    return FIXED_CONVENTION.theta(np.stack([waist, shoulder, elbow], axis=-1))


def effort_from_tau(tau: np.ndarray) -> np.ndarray:
    """The torques (N m) conjugate to the older drivers' coordinates (waist, shoulder, elbow;
    FIXED_CONVENTION) of the report's tau (N m, (3,) or (..., 3)): (tau1, tau2 + tau3, tau3),
    the effort of their joint_states."""
    return FIXED_CONVENTION.effort(tau)


def theta_from_joint_state(names: object, position: object, prefix: str = "",
                           convention: JointConvention = FIXED_CONVENTION) -> np.ndarray:
    """The report's theta (rad) of a driver's joint_states: ``names`` (sequence of str, as in
    sensor_msgs/JointState, each joint of JOINT_STATE_NAMES with ``prefix`` exactly once;
    others, such as the gimbal's (gimbal_from_joint_state), are ignored) and ``position`` (rad,
    one value per name, or (N, len(names)) for a batch), read in ``convention`` (default
    FIXED_CONVENTION: theta = (waist, shoulder, shoulder + elbow); for kinisi's or CalaW's driver
    pass its profile's joint_states.convention). Velocities (rad/s) convert the same way."""
    reader = _reader(convention)
    wanted = [_prefix(prefix) + name for name in JOINT_STATE_NAMES]
    given = _names(names, wanted)
    values, _ = as_states(position, "position", width=len(given))
    published = np.stack([values[..., given.index(name)] for name in wanted], axis=-1)
    with np.errstate(over="ignore"):  # reported by finite_result, naming position
        return finite_result(reader.theta(published), "position")


def joint_state_from_theta(theta: object, prefix: str = "",
                           convention: JointConvention = FIXED_CONVENTION) -> tuple[list[str], np.ndarray]:
    """(names, position) of the drivers' joint_states for the report's theta (rad), (3,) or
    (..., 3), in ``convention`` (default FIXED_CONVENTION: [prefix + waist, shoulder, elbow],
    (theta1, theta2, theta3 - theta2))."""
    reader = _reader(convention)
    t, _ = as_states(theta, "theta")
    names = [_prefix(prefix) + name for name in JOINT_STATE_NAMES]
    with np.errstate(over="ignore"):  # reported by finite_result, naming theta
        return names, finite_result(reader.published(t), "theta")
