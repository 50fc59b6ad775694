"""The public ROS drivers of the Touch / Omni, as data: one profile per driver.

Each profile (robots/phantom_description/config/drivers/NAME.yaml, every fact with the driver's
source file and line at a stated commit) says what the driver publishes as joint states and how
it takes a force: the topic, the message type and its quality of service, the frame of the
force vector (a matrix A from the message's three numbers to OpenHaptics' HD_CURRENT_FORCE:
F_OH = A F_msg), the clamp and damping the driver applies itself, and its rate.

OpenHaptics' frame (OH) has the axes of the report's frame s (x to the user's right, y up, z
towards the user; phantom_pin.interfaces.conventions), so a force in OH is a force in frame s (N). Every
public driver takes a Cartesian force in newtons and sends it with hdSetDoublev(
HD_CURRENT_FORCE); OpenHaptics renders it at the gimbal centre (the tool frame t, ``tip``):
the joint torques are J_p(theta)^T F, J_p the tip's position Jacobian in frame s
(Device.tip_jacobian). See docs/drivers.md.

Joint states: each profile's phantom_pin.interfaces.conventions.JointConvention (``published = sign * a`` for
OpenHaptics' raw arm angles a (HD_CURRENT_JOINT_ANGLES, rad), the elbow ``relative`` (sign3 *
(a3 - a2)) or ``absolute`` (sign3 * a3); the gimbal ``published = sign * g + offset``
(HD_CURRENT_GIMBAL_ANGLES, rad)), the one reader that the ``ros2`` node without a driver and
urdf/touch_driver.urdf use too (drivers.FIXED_CONVENTION). The report's theta is (-a1,
a2, a3) (phantom_pin.interfaces.conventions).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from functools import cache

import numpy as np

from phantom_pin._paths import PROFILES_DIR
from phantom_pin.config.files import read_yaml
from phantom_pin.exceptions import InvalidInputError, ParameterFileError
from phantom_pin.interfaces.conventions import JointConvention, convention_of

__all__ = ["Profile", "JointStates", "ForceCommand", "StateTopic", "Qos", "load", "names", "relayed"]

#: The force message types a driver takes (the fields read; omni_msgs is built in a ROS workspace).
FORCE_TYPES = ("geometry_msgs/msg/Vector3", "geometry_msgs/msg/Wrench", "geometry_msgs/msg/WrenchStamped",
               "omni_msgs/msg/OmniFeedback")


@dataclasses.dataclass(frozen=True)
class Qos:
    """A topic's quality of service: ``reliability`` ("reliable" or "best_effort"), ``depth``."""

    reliability: str
    depth: int


@dataclasses.dataclass(frozen=True)
class JointStates:
    """What a driver publishes as sensor_msgs/JointState: ``topic``, ``names`` (the six, in
    order: three of the arm, three of the gimbal), ``convention`` (conventions.JointConvention: the
    arm's signs and elbow, the gimbal's signs and offsets), ``effort_unit`` ("mN m" where it
    publishes OpenHaptics' joint torques, else None), ``qos``, ``rate`` (Hz)."""

    topic: str
    names: tuple[str, ...]
    convention: JointConvention
    effort_unit: str | None
    qos: Qos
    rate: float


@dataclasses.dataclass(frozen=True)
class ForceCommand:
    """How a driver takes a force: ``topic``, ``type`` (FORCE_TYPES), ``field`` (the Vector3
    read: "force", "wrench.force", or None for a Vector3 itself), ``header`` (whether the type
    has one), ``to_openhaptics`` (A, 3x3 signed permutation: F_OH = A F_msg), ``qos``,
    ``clamp`` (N, the largest norm it sends; inf for none), ``damping`` (N s/m, F_OH -= damping *
    v_OH each servo tick), ``spring`` (N/m towards the start-up position, each axis; 0 for none),
    ``hold`` ("held": the last command every servo tick; "one_tick": only the tick after each
    message), ``nan_to_zero`` (whether it zeroes non-finite components)."""

    topic: str
    type: str
    field: str | None
    header: bool
    to_openhaptics: np.ndarray
    qos: Qos
    clamp: float
    damping: float
    spring: float
    hold: str
    nan_to_zero: bool


@dataclasses.dataclass(frozen=True)
class StateTopic:
    """A state topic a driver publishes beside its joint states, of a type that installs here:
    ``topic``, ``type`` (STATE_TYPES), ``frame_id``; its vectors are ``axes`` @ OpenHaptics'
    (a pose's position HD_CURRENT_TRANSFORM's translation in m, a twist's linear velocity in m/s
    and angular in rad/s), a pose's rotation C @ R_OH @ C^T @ ``after`` with C =
    ``rotation_axes`` (the same as ``axes`` unless a driver turns its position only)."""

    topic: str
    type: str
    frame_id: str
    axes: np.ndarray
    after: np.ndarray
    rotation_axes: np.ndarray


@dataclasses.dataclass(frozen=True)
class Profile:
    """One driver: ``name``, ``description``, ``joint_states``, ``force``, ``sources`` (the
    repositories read: owner/name@commit)."""

    name: str
    description: str
    joint_states: JointStates
    force: ForceCommand
    sources: tuple[str, ...]
    state_topics: tuple[StateTopic, ...] = ()

    # -- joint states ------------------------------------------------------------------
    def arm_from_state(self, published: Sequence[float]) -> np.ndarray:
        """The report's theta (rad) of the driver's three published arm angles (rad)."""
        return self.joint_states.convention.theta(published)

    def state_from_arm(self, theta: Sequence[float]) -> np.ndarray:
        """The driver's three published arm angles (rad) of the report's theta (rad)."""
        return self.joint_states.convention.published(theta)

    def gimbal_from_state(self, published: Sequence[float]) -> np.ndarray:
        """OpenHaptics' raw gimbal angles (rad) of the driver's three published ones (rad)."""
        return self.joint_states.convention.gimbal(published)

    def state_from_gimbal(self, gimbal: Sequence[float]) -> np.ndarray:
        """The driver's three published gimbal angles (rad) of OpenHaptics' raw ones (rad)."""
        return self.joint_states.convention.published_gimbal(gimbal)

    # -- forces ------------------------------------------------------------------------
    def message_from_openhaptics(self, force: np.ndarray) -> np.ndarray:
        """The message's three numbers (N) that make the driver send ``force`` (N, OH frame)."""
        return self.force.to_openhaptics.T @ force

    def openhaptics_from_message(self, force: np.ndarray) -> np.ndarray:
        """HD_CURRENT_FORCE's direction and size (N, OH) of the message's three numbers (N),
        before the driver's own clamp, damping and spring."""
        return self.force.to_openhaptics @ force


#: The state topics' types sim-driver publishes.
STATE_TYPES = ("geometry_msgs/msg/PoseStamped", "geometry_msgs/msg/TwistStamped")


#: The suffix of the relay's topic (relayed()).
RELAY = "_relay"


def relayed(profile: Profile) -> Profile:
    """The profile with its force sent as geometry_msgs/Vector3 (the same three numbers, N, the
    driver's frame) on its force topic + RELAY, for a one-file relay in the driver's workspace to
    put into its own message type (omni_msgs is not on PyPI: docs/drivers.md)."""
    force = dataclasses.replace(profile.force, topic=profile.force.topic + RELAY, type=FORCE_TYPES[0], field=None,
                                header=False)
    return dataclasses.replace(profile, force=force)


def names() -> tuple[str, ...]:
    """The profiles' names, sorted."""
    return tuple(sorted(path.stem for path in PROFILES_DIR.glob("*.yaml")))


def _qos(node: dict, where: str) -> Qos:
    reliability, depth = node.get("reliability"), node.get("depth")
    if reliability not in ("reliable", "best_effort") or not isinstance(depth, int) or depth < 1:
        raise ParameterFileError(f"{where}: expected reliability reliable|best_effort and depth >= 1, got {node}")
    return Qos(reliability, depth)


def _joint_states(node: dict, where: str) -> JointStates:
    convention = convention_of(node, where)
    names_ = node["names"]
    if not isinstance(names_, list) or len(names_) != 6 or len(set(names_)) != 6:
        raise ParameterFileError(f"{where}.names: expected six distinct joint names, got {names_!r}")
    unit = node["effort"].get("unit")
    if unit not in (None, "mN m"):
        raise ParameterFileError(f"{where}.effort.unit: expected null or 'mN m', got {unit!r}")
    rate = node["rate"]
    if not isinstance(rate, (int, float)) or not rate > 0:
        raise ParameterFileError(f"{where}.rate: expected a rate in Hz, got {rate!r}")
    return JointStates(str(node["topic"]), tuple(map(str, names_)), convention, unit,
                       _qos(node["qos"], f"{where}.qos"), float(rate))


def _axes(value: object, where: str) -> np.ndarray:
    """A rotation that permutes and signs axes (3x3), else ParameterFileError at ``where``."""
    matrix = np.array(value, dtype=float)
    if matrix.shape != (3, 3) or not np.array_equal(matrix @ matrix.T, np.eye(3)) or not set(
            np.abs(matrix).ravel()) <= {0.0, 1.0} or round(np.linalg.det(matrix)) != 1:
        raise ParameterFileError(f"{where}: expected a rotation that permutes and signs axes, got {value}")
    return matrix


def _state_topics(nodes: list, where: str) -> tuple[StateTopic, ...]:
    topics = []
    for k, node in enumerate(nodes):
        if node["type"] not in STATE_TYPES:
            raise ParameterFileError(f"{where}[{k}].type: expected one of {', '.join(STATE_TYPES)}, "
                                     f"got {node['type']!r}")
        after, turned = node.get("after", np.eye(3).tolist()), node.get("rotation_axes", node["axes"])
        topics.append(StateTopic(str(node["topic"]), node["type"], str(node["frame_id"]),
                                 _axes(node["axes"], f"{where}[{k}].axes"), _axes(after, f"{where}[{k}].after"),
                                 _axes(turned, f"{where}[{k}].rotation_axes")))
    return tuple(topics)


def _force(node: dict, where: str) -> ForceCommand:
    if node["type"] not in FORCE_TYPES:
        raise ParameterFileError(f"{where}.type: expected one of {', '.join(FORCE_TYPES)}, got {node['type']!r}")
    matrix = _axes(node["to_openhaptics"], f"{where}.to_openhaptics")
    clamp = node["clamp"]
    limit = math.inf if clamp["kind"] == "none" else float(clamp["value"])
    if clamp["kind"] not in ("none", "norm") or not limit > 0:
        raise ParameterFileError(f"{where}.clamp: expected kind none or norm with a value > 0 N, got {clamp}")
    damping = float((node.get("damping") or {}).get("value", 0.0))
    spring = float((node.get("impedance_spring") or {}).get("value", 0.0))
    if not (damping >= 0 and spring >= 0 and math.isfinite(damping + spring)):
        raise ParameterFileError(f"{where}: damping and spring must be finite and >= 0, got {damping}, {spring}")
    if node["hold"] not in ("held", "one_tick"):
        raise ParameterFileError(f"{where}.hold: expected held or one_tick, got {node['hold']!r}")
    field = node["field"]
    expected = {"geometry_msgs/msg/Vector3": None, "geometry_msgs/msg/Wrench": "force",
                "geometry_msgs/msg/WrenchStamped": "wrench.force", "omni_msgs/msg/OmniFeedback": "force"}
    if field != expected[node["type"]] or bool(node["header"]) != node["type"].endswith("Stamped"):
        raise ParameterFileError(f"{where}: field {field!r} / header {node['header']!r} do not fit {node['type']}")
    return ForceCommand(str(node["topic"]), node["type"], field, bool(node["header"]), matrix,
                        _qos(node["qos"], f"{where}.qos"), limit, damping, spring, node["hold"],
                        node["nan_to_zero"] is True)


@cache
def load(name: str) -> Profile:
    """The profile ``name`` (names()); InvalidInputError naming ``driver`` for an unknown one,
    ParameterFileError for a file that does not hold a profile."""
    if not isinstance(name, str) or name not in names():
        raise InvalidInputError(f"unknown driver profile {name!r} (known: {', '.join(names())})", argument="driver")
    path = PROFILES_DIR / f"{name}.yaml"
    node = read_yaml(path)
    try:
        return Profile(node["name"], node["description"], _joint_states(node["joint_states"], f"{path}: joint_states"),
                       _force(node["force"], f"{path}: force"),
                       tuple(f"{r['repo']}@{str(r['commit'])[:7]}" for r in node["repositories"]),
                       _state_topics(node["state_topics"], f"{path}: state_topics"))
    except (KeyError, TypeError) as error:
        raise ParameterFileError(f"{path}: not a driver profile ({error!r} missing or malformed)") from None
