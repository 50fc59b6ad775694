"""A ROS 2 node: the drivers' joint_states in, the gravity torques and the tip's and stylus's
poses out, per message, with the message's stamp (the ``ros2`` extra: rclpy and the message
packages from PyPI).

Input, ``joint_states`` (sensor_msgs/JointState): the older drivers' names and fixed convention
(conventions.FIXED_CONVENTION, the one urdf/touch_driver.urdf is jointed in: ``waist,
shoulder, elbow`` = theta1, theta2, theta3 - theta2, and, for a model with a stylus gimbal,
``yaw, pitch, roll``, OpenHaptics' raw gimbal angles; sawSensablePhantom publishes it; kinisi's,
CalaW's and RViMLab's drivers do not: read them with ``--driver``, DriverBridge), or the
model's own (``joint1..joint3``, ``joint4..joint6``), each with the node's prefix; the gimbal's
under either set of names, whichever names the arm. Other names are ignored; without the
gimbal's names the gimbal is taken at its ``locked_at``.

Output, every message carrying the input's header stamp:

- ``gravity_torque`` (sensor_msgs/JointState): the joint torques that hold the arm (N m), as
  effort on the input's own joint names: for the drivers' names the torques conjugate to
  their coordinates (waist, shoulder, elbow): (tau1, tau2 + tau3, tau3) (FIXED_CONVENTION.effort), tau the report's
  (Phantom.gravity); for the model's names tau itself. Position and velocity are empty.
- ``gravity_torque_openhaptics`` (sensor_msgs/JointState): the same torques as
  HD_CURRENT_JOINT_TORQUE takes them (mN m, on OpenHaptics' angles and signs:
  conventions.openhaptics_torque_from_tau), named ``turret, thigh, shin`` (OpenHaptics' guide).
- ``tip_pose`` (geometry_msgs/PoseStamped): the tool frame t (the gimbal centre) in
  ``base_link`` (REP-103: x forward, y left, z up; metres).
- ``stylus_pose`` (geometry_msgs/PoseStamped, a model with a gimbal): the stylus tip, with the
  stylus's orientation (Phantom.stylus_tip_pose), in ``base_link``.
- ``model_joint_states`` (sensor_msgs/JointState): every joint of the model's URDF (the mimic
  joints of the parallelogram included), rad, for robot_state_publisher with that URDF.

A message with a missing name, a name it reads given twice, some of the gimbal's three names but
not all (the drivers' or the model's: either set goes with either arm's), a position or velocity
field whose length does not match its names (an empty velocity is fine), a value that is not
finite or an angle more than a turn beyond the stops is dropped with one warning per second
naming the field; the node keeps running. Quality of service: the subscription is best effort
(a 1 kHz sensor stream: it matches reliable and best-effort publishers alike), keep last 10: a
node slower than the stream answers the newest messages, not a growing backlog (rclpy's Python
executor answers 690-840 messages per second on a 2-core machine, tests/interfaces/ros2/test_node.py); the
publishers reliable, depth 100.
"""

from __future__ import annotations

import dataclasses
import gc
import importlib
import math
import threading
import time
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np
import pinocchio as pin

from phantom_pin.config.types import GIMBAL_JOINTS, JOINTS, Friction
from phantom_pin.dynamics.phantom import Phantom
from phantom_pin.exceptions import InvalidInputError, MissingDataError
from phantom_pin.interfaces import conventions
from phantom_pin.interfaces.forces import Frames, Renderer, Vector
from phantom_pin.interfaces.profiles import Profile, Qos

__all__ = ["Bridge", "DriverBridge", "Output", "make_node", "spin", "run", "message_type", "fill_force"]

#: The topics, by role: the input and the five outputs (module doc), relative names.
TOPICS = {"joint_states": "joint_states", "wrench": "wrench", "gravity_torque": "gravity_torque",
          "gravity_torque_openhaptics": "gravity_torque_openhaptics", "tip_pose": "tip_pose",
          "stylus_pose": "stylus_pose", "model_joint_states": "model_joint_states"}
#: The joint_states convention read without a driver (the older drivers'; drivers' module doc).
FIXED = conventions.FIXED_CONVENTION
#: OpenHaptics' names of its three joints (its reference guide: "Turet Left +, Thigh Up +, Shin Up +").
OPENHAPTICS_NAMES = ("turret", "thigh", "shin")
#: A message is dropped when an angle lies more than this beyond its stop (rad): a turn.
BEYOND = 2 * math.pi
#: Queue depth of the subscription (messages): 10 ms at 1 kHz. A node that falls behind the
#: stream answers the newest messages and lets stale ones go (a torque for a posture 0.5 s old
#: is of no use to a servo loop); the publishers' depth (reliable) is DEPTH_OUT.
DEPTH = 10
DEPTH_OUT = 100
#: With a driver, the gravity torques, poses and model joint states follow at most this rate (Hz):
#: enough for RViz and a logger, and the servo path (the force) is answered first and alone.
OUTPUTS_RATE = 100.0
#: The largest user force the node takes, per axis (N): far above any haptic device's.
MAX_USER_FORCE = 100.0


@dataclasses.dataclass(frozen=True)
class Output:
    """What one joint_states message gives: the input's names and the gravity torques on them
    (N m), OpenHaptics' torques (mN m), the tip's and the stylus's poses in base_link ((4, 4)
    m; the stylus's None without a gimbal) and the model's every joint (names, rad)."""

    names: tuple[str, ...]
    effort: np.ndarray
    openhaptics: np.ndarray
    tip: np.ndarray
    stylus: np.ndarray | None
    model_names: tuple[str, ...]
    model_positions: np.ndarray


def _box(phantom: Phantom) -> tuple[np.ndarray, np.ndarray]:
    """The box a message's angles must lie in (rad): the stops, and the gimbal's ranges where the
    model has one, BEYOND wider on each side."""
    stops, gimbal = phantom.config.limits.stops, phantom.config.gimbal
    lower = np.array([*stops.lower, *(gimbal.lower if gimbal else ())]) - BEYOND
    upper = np.array([*stops.upper, *(gimbal.upper if gimbal else ())]) + BEYOND
    return lower, upper


def _names(names: Sequence[str], positions: Sequence[float], velocity: Sequence[float]) -> list[str]:
    """A joint_states message's names, its position one value per name and its velocity empty
    or one value per name; InvalidInputError naming the field otherwise."""
    given = list(names)
    if len(positions) != len(given):
        raise InvalidInputError(f"{len(positions)} values for {len(given)} names", argument="position")
    if len(velocity) not in (0, len(given)):
        raise InvalidInputError(f"{len(velocity)} values for {len(given)} names (one per name, or none)",
                                argument="velocity")
    return given


class DriverBridge:
    """The force path's computation, without ROS: a driver's joint_states (its profile's names,
    each with the description's prefix, exactly once; its conventions) to theta and g, a user's
    WrenchStamped to frame s, and the force the driver must send (forces.Renderer).
    InvalidInputError naming the field of a message that must be dropped."""

    def __init__(self, phantom: Phantom, profile: Profile, compensate: Sequence[str] = ("gravity",),
                 max_force: float = math.inf, friction: Friction | None = None, kappa: float = 0.0) -> None:
        self.phantom, self.profile = phantom, profile
        self.renderer = Renderer(phantom, profile, compensate, max_force, friction, kappa)
        self.frames = Frames(phantom)
        prefix = phantom.description.prefix
        self.names = tuple(prefix + n for n in profile.joint_states.names)
        self.gimbal = phantom.config.gimbal
        self.lower, self.upper = _box(phantom)

    def state(self, names: Sequence[str], positions: Sequence[float],
              velocity: Sequence[float] = ()) -> tuple[np.ndarray, np.ndarray | None]:
        """(theta, g) (rad) of one joint_states message; g None for a model without a gimbal.
        ``velocity`` (its velocity field) is checked only: empty or one value per name."""
        given = _names(names, positions, velocity)
        wanted = self.names if self.gimbal is not None else self.names[:3]
        wrong = [n for n in wanted if given.count(n) != 1]
        if wrong:
            raise InvalidInputError(f"must hold each of {', '.join(wanted)} once; {', '.join(wrong)} not, in {given}",
                                    argument="name")
        values = [float(positions[given.index(n)]) for n in wanted]
        if not math.isfinite(sum(values)):
            raise InvalidInputError("not finite (NaN or inf)", argument="position")
        theta = self.profile.arm_from_state(values[:3])
        gimbal = None if self.gimbal is None else self.profile.gimbal_from_state(values[3:])
        state = self.frames.state(theta, gimbal)
        outside = [i for i in range(len(state)) if not self.lower[i] <= state[i] <= self.upper[i]]
        if outside:
            raise InvalidInputError(f"{wanted[outside[0]]} = {values[outside[0]]:.4g} rad is more than a turn "
                                    "beyond its stop", argument="position")
        return theta, gimbal

    def wrench(self, frame: str, force: Sequence[float]) -> tuple[str, tuple[float, float, float]]:
        """A user's WrenchStamped's frame_id and force (N), checked: a frame of the model's URDF
        ("" is base_link) and finite values of at most MAX_USER_FORCE N."""
        values = tuple(float(v) for v in force)
        if len(values) != 3 or not all(math.isfinite(v) and abs(v) <= MAX_USER_FORCE for v in values):
            raise InvalidInputError(f"expected three finite values of at most {MAX_USER_FORCE:g} N, got {values}",
                                    argument="force")
        if frame not in ("", self.frames.prefix + "base_link") and frame not in self.frames.names:
            raise InvalidInputError(f"{frame!r} is not a frame of the model", argument="frame_id")
        return frame, (values[0], values[1], values[2])

    def user_force(self, frame: str, force: Sequence[float], theta: np.ndarray,
                   gimbal: np.ndarray | None) -> np.ndarray:
        """The user's force (N, given in ``frame``, checked by ``wrench``) in frame s at (theta, g)."""
        return self.frames.rotation(frame, theta, gimbal) @ np.asarray(force, dtype=float)


class Bridge:
    """The node's computation, without ROS: ``__call__(names, positions)`` -> Output, or
    InvalidInputError naming the field of a message that must be dropped. The joint and frame
    names carry the prefix of the Phantom's description (describe(..., prefix=...))."""

    def __init__(self, phantom: Phantom) -> None:
        if not isinstance(phantom, Phantom):
            raise InvalidInputError(f"expected a phantom_pin.Phantom, got {phantom!r}", argument="phantom")
        self.phantom = phantom
        self.prefix = prefix = phantom.description.prefix
        self.gimbal = phantom.config.gimbal
        self.driver_names = tuple(prefix + n for n in conventions.JOINT_STATE_NAMES)
        self.driver_gimbal = tuple(prefix + n for n in conventions.GIMBAL_STATE_NAMES)
        self.model_arm = tuple(prefix + n for n in JOINTS)
        self.model_gimbal = tuple(prefix + n for n in GIMBAL_JOINTS)
        # box of each input angle: the stops a turn wide on each side (theta; the gimbal's ranges)
        self.lower, self.upper = _box(phantom)
        self.frames = Frames(phantom)   # every joint of the URDF, the gimbal free; frame s in base_link
        self.full, self.base_from_s = self.frames.full, self.frames.base_from_s
        self.model_names = tuple(self.full.tree.names[1:])

    def _values(self, names: Sequence[str], positions: Sequence[float],
                velocity: Sequence[float]) -> tuple[dict[str, float], bool]:
        """The input by name, and whether it uses the drivers' names (else the model's)."""
        given = _names(names, positions, velocity)
        read = (*self.driver_names, *self.model_arm, *self.driver_gimbal, *self.model_gimbal)
        twice = [n for n in read if given.count(n) > 1]
        if twice:
            raise InvalidInputError(f"{', '.join(twice)} given more than once, in {given}", argument="name")
        values = dict(zip(given, (float(p) for p in positions)))
        driver = all(n in values for n in self.driver_names)
        if not driver and not all(n in values for n in self.model_arm):
            raise InvalidInputError(f"missing {', '.join(n for n in self.driver_names if n not in values)} (or "
                                    f"{', '.join(self.model_arm)}), in {given}", argument="name")
        return values, driver

    def _gimbal(self, values: dict[str, float]) -> np.ndarray | None:
        """The raw gimbal angles of the input, under the drivers' names or the model's (either
        with either arm's), or None (locked_at) where it names none of them; a model without a
        gimbal ignores them all."""
        if self.gimbal is None:
            return None
        named = [names for names in (self.driver_gimbal, self.model_gimbal) if any(n in values for n in names)]
        if not named:
            return None
        if len(named) > 1:
            raise InvalidInputError(f"the gimbal given twice, as {', '.join(self.driver_gimbal)} and as "
                                    f"{', '.join(self.model_gimbal)}", argument="name")
        missing = [n for n in named[0] if n not in values]
        if missing:
            raise InvalidInputError(f"missing {', '.join(missing)}: give the gimbal's three angles or none "
                                    f"(none: its locked_at), in {list(values)}", argument="name")
        return FIXED.gimbal([values[n] for n in named[0]])  # raw angles (the older drivers' and the model's)

    def __call__(self, names: Sequence[str], positions: Sequence[float], velocity: Sequence[float] = ()) -> Output:
        """Output of one joint_states message; ``velocity`` (its velocity field) is checked only:
        empty or one value per name."""
        values, driver = self._values(names, positions, velocity)
        arm = [values[n] for n in (self.driver_names if driver else self.model_arm)]
        theta = FIXED.theta(arm) if driver else np.array(arm)
        gimbal = self._gimbal(values)
        state = np.concatenate([theta, gimbal if gimbal is not None else
                                (self.gimbal.locked_at if self.gimbal else [])])
        if not np.isfinite(state).all():
            raise InvalidInputError("not finite (NaN or inf)", argument="position")
        outside = [i for i in range(len(state)) if not self.lower[i] <= state[i] <= self.upper[i]]
        if outside:
            label = ("theta1", "theta2", "theta3", "gimbal1", "gimbal2", "gimbal3")[outside[0]]
            raise InvalidInputError(f"{label} = {state[outside[0]]:.4g} rad is more than a turn beyond its stop",
                                    argument="position")
        phantom = self.phantom
        tau = phantom.gravity(theta) if gimbal is None else phantom.gravity(theta, gimbal)
        effort = FIXED.effort(tau) if driver else tau
        tip = self.base_from_s @ phantom.forward_kinematics(theta)
        stylus = None if gimbal is None else self.base_from_s @ phantom.stylus_tip_pose(theta, gimbal)
        return Output(tuple(self.driver_names if driver else self.model_arm), effort,
                      conventions.openhaptics_torque_from_tau(tau), tip, stylus, self.model_names,
                      self.full.configuration(state))


def _pose(message, pose: np.ndarray, stamp, frame: str) -> None:
    """Fill a geometry_msgs/PoseStamped from a (4, 4) pose (m)."""
    message.header.stamp, message.header.frame_id = stamp, frame
    p = message.pose.position
    p.x, p.y, p.z = (float(v) for v in pose[:3, 3])
    q = pin.Quaternion(pose[:3, :3])
    o = message.pose.orientation
    o.x, o.y, o.z, o.w = float(q.x), float(q.y), float(q.z), float(q.w)


def message_type(name: str) -> type:
    """The Python class of a ROS message type ``pkg/msg/Name``; MissingDataError naming
    ``driver`` where its package is not installed (omni_msgs: build it in the driver's workspace)."""
    package, _, kind = name.split("/")
    try:
        return getattr(importlib.import_module(f"{package}.msg"), kind)
    except (ImportError, AttributeError):
        raise MissingDataError(f"the driver's message type {name} is not installed here (omni_msgs is not on "
                               "PyPI: source the driver's ROS 2 workspace, or add --relay and run the relay of "
                               "docs/drivers.md)",
                               argument="driver") from None


def _qos(qos: Qos):
    from rclpy.qos import QoSProfile, ReliabilityPolicy

    return QoSProfile(depth=qos.depth, reliability=ReliabilityPolicy.RELIABLE if qos.reliability == "reliable"
                      else ReliabilityPolicy.BEST_EFFORT)


def fill_force(message, profile: Profile, force: Vector, stamp=None) -> None:
    """Write the driver's three numbers (N, its frame) into its force ``message`` (and ``stamp``
    into its header where the type has one)."""
    vector = message
    for part in (profile.force.field or "").split("."):
        vector = getattr(vector, part) if part else vector
    vector.x, vector.y, vector.z = (float(v) for v in force)
    if profile.force.header and stamp is not None:
        message.header.stamp = stamp


def make_node(phantom: Phantom, topics: Mapping[str, str] | None = None, name: str = "phantom_pin",
              driver: DriverBridge | None = None):
    """The rclpy node (rclpy.init must have run): subscribes TOPICS["joint_states"] (renamed by
    ``topics``) and publishes the module doc's outputs per message; names with the prefix of
    the Phantom's description. With a ``driver``: subscribes its profile's joint states
    instead, the user's force on ``wrench`` (geometry_msgs/WrenchStamped), and publishes the
    profile's force command first, then the outputs above on the model's joint names."""
    from geometry_msgs.msg import PoseStamped, WrenchStamped
    from rclpy.node import Node
    from rclpy.qos import QoSProfile, ReliabilityPolicy
    from sensor_msgs.msg import JointState

    bridge = Bridge(phantom)
    prefix = bridge.prefix
    names = _topic_names(topics, driver)
    model_names = [*bridge.model_arm, *(bridge.model_gimbal if bridge.gimbal is not None else ())]
    force_type: Any = None if driver is None else message_type(driver.profile.force.type)

    class GravityNode(Node):
        def __init__(self) -> None:
            super().__init__(name)
            if driver is not None:  # first: the force command, the servo loop's path
                self.force: Any = self.create_publisher(force_type, driver.profile.force.topic,
                                                   _qos(driver.profile.force.qos))
                self.create_subscription(WrenchStamped, names["wrench"], self.on_wrench,
                                         QoSProfile(depth=DEPTH, reliability=ReliabilityPolicy.BEST_EFFORT))
                self.user: tuple[str, tuple[float, float, float]] = ("", (0.0, 0.0, 0.0))
            reliable = QoSProfile(depth=DEPTH_OUT, reliability=ReliabilityPolicy.RELIABLE)
            self.outputs = {role: self.create_publisher(kind, names[role], reliable) for role, kind in (
                ("gravity_torque", JointState), ("gravity_torque_openhaptics", JointState),
                ("tip_pose", PoseStamped), ("model_joint_states", JointState),
                *((("stylus_pose", PoseStamped),) if bridge.gimbal is not None else ()))}
            self.create_subscription(JointState, names["joint_states"], self.on_joint_states,
                                     QoSProfile(depth=DEPTH, reliability=ReliabilityPolicy.BEST_EFFORT))
            self.dropped = 0
            self.next_outputs = 0.0   # s, monotonic: when the driver's path publishes the outputs next
            self.warned: set[str] = set()

        def on_wrench(self, message) -> None:
            _on_wrench(self, driver, message)  # type: ignore[arg-type]  # only with a driver

        def on_joint_states(self, message) -> None:
            stamp = message.header.stamp
            try:
                out = bridge(message.name, message.position, message.velocity) if driver is None else \
                    self.serve(driver.state(message.name, message.position, message.velocity), stamp)
            except InvalidInputError as error:
                self.dropped += 1
                self.get_logger().warning(f"dropped a joint_states message: {error}", throttle_duration_sec=1.0)
                return
            if out is not None:
                self.publish_outputs(out, stamp, message.header.frame_id)

        def serve(self, state: tuple[np.ndarray, np.ndarray | None], stamp) -> Output | None:
            """The driver's path: the force command first; the outputs at OUTPUTS_RATE, and only
            while someone listens (else None)."""
            theta, gimbal = state
            self.send_force(theta, gimbal, stamp)
            now = time.monotonic()
            if now < self.next_outputs:
                return None
            self.next_outputs = now + 1.0 / OUTPUTS_RATE
            if not any(p.get_subscription_count() for p in self.outputs.values()):
                return None
            return bridge(model_names, [*theta, *(gimbal if gimbal is not None else ())])

        def send_force(self, theta: np.ndarray, gimbal: np.ndarray | None, stamp) -> None:
            _send_force(self, driver, force_type, theta, gimbal, stamp)  # type: ignore[arg-type]

        def publish_outputs(self, out: Output, stamp, frame_id: str) -> None:
            _publish_outputs(self.outputs, out, stamp, frame_id, prefix)

    return GravityNode()


def _topic_names(topics: Mapping[str, str] | None, driver: DriverBridge | None) -> dict[str, str]:
    """The topic of each role (TOPICS renamed by ``topics``; a driver's joint states by its
    profile unless renamed); InvalidInputError naming ``topics`` for an unknown role."""
    names = {**TOPICS, **(topics or {})}
    if driver is not None and "joint_states" not in (topics or {}):
        names["joint_states"] = driver.profile.joint_states.topic
    unknown = sorted(set(names) - set(TOPICS))
    if unknown:
        raise InvalidInputError(f"unknown topic roles {unknown} (known: {', '.join(TOPICS)})", argument="topics")
    return names


def _on_wrench(node, driver: DriverBridge, message) -> None:
    """Keep a user's WrenchStamped (checked) as the node's ``user`` force; a throttled warning
    where it is dropped, one warning ever that its torque part is ignored."""
    force, torque = message.wrench.force, message.wrench.torque
    try:
        node.user = driver.wrench(message.header.frame_id, (force.x, force.y, force.z))
    except InvalidInputError as error:
        node.get_logger().warning(f"dropped a wrench message: {error}", throttle_duration_sec=1.0)
        return
    if (torque.x or torque.y or torque.z) and "torque" not in node.warned:
        node.warned.add("torque")
        node.get_logger().warning("wrench: its torque part is ignored (the arm has three motors: a force at "
                                  "the gimbal centre only)")


def _send_force(node, driver: DriverBridge, force_type: type, theta: np.ndarray, gimbal: np.ndarray | None,
                stamp) -> None:
    """Publish the driver's force command for one state (rad), its header stamped ``stamp``;
    throttled warnings where it was clamped or damped near a singularity."""
    frame, values = node.user
    user = driver.user_force(frame, values, theta, gimbal)
    seconds = stamp.sec + 1e-9 * stamp.nanosec
    rendered = driver.renderer(theta, gimbal, user, seconds if seconds > 0 else time.time())
    command = force_type()
    fill_force(command, driver.profile, rendered.message, stamp)
    node.force.publish(command)
    if rendered.scale < 1.0:
        node.get_logger().warning(f"force clamped to {np.linalg.norm(rendered.openhaptics):.3g} N (x "
                                  f"{rendered.scale:.3g}: the driver's clamp, the motors or --max-force)",
                                  throttle_duration_sec=1.0)
    if rendered.singular:
        node.get_logger().warning(f"near a singularity (smallest singular value of J {rendered.sigma_min:.2e} "
                                  "m/rad): damped inverse", throttle_duration_sec=1.0)


def _publish_outputs(outputs: dict, out: Output, stamp, frame_id: str, prefix: str) -> None:
    """Publish today's outputs of one message (the module doc)."""
    from geometry_msgs.msg import PoseStamped
    from sensor_msgs.msg import JointState

    base = prefix + "base_link"
    effort = JointState()
    effort.header.stamp, effort.header.frame_id = stamp, frame_id
    effort.name, effort.effort = list(out.names), [float(v) for v in out.effort]
    outputs["gravity_torque"].publish(effort)
    hd = JointState()
    hd.header.stamp = stamp
    hd.name, hd.effort = [prefix + n for n in OPENHAPTICS_NAMES], [float(v) for v in out.openhaptics]
    outputs["gravity_torque_openhaptics"].publish(hd)
    tip = PoseStamped()
    _pose(tip, out.tip, stamp, base)
    outputs["tip_pose"].publish(tip)
    if out.stylus is not None:
        stylus = PoseStamped()
        _pose(stylus, out.stylus, stamp, base)
        outputs["stylus_pose"].publish(stylus)
    full = JointState()
    full.header.stamp = stamp
    full.name, full.position = list(out.model_names), [float(v) for v in out.model_positions]
    outputs["model_joint_states"].publish(full)


def spin(phantom: Phantom, topics: Mapping[str, str] | None = None, driver: DriverBridge | None = None) -> int:
    """Run the node (make_node) until SIGINT or SIGTERM; 0 on a clean stop."""
    return run(lambda: make_node(phantom, topics, driver=driver),
               f"phantom_pin {phantom.config.name}: joint_states -> "
               f"{driver.profile.force.topic + ', ' if driver is not None else ''}gravity, poses")


def run(make: Callable[[], Any], ready: str, loop: Callable[[Any, threading.Event], None] | None = None) -> int:
    """Run the node ``make()`` builds until SIGINT or SIGTERM, logging ``ready`` once it spins;
    0 on a clean stop. A worker thread spins the executor, or runs ``loop(executor, stop)``
    (which must return once ``stop`` is set); the signals set ``stop``, which the main thread
    reads every 0.1 s, then shuts the executor down (rclpy's own handlers are not installed:
    with them, a SIGTERM now and then left the node spinning in CI)."""
    import signal

    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.signals import SignalHandlerOptions

    stop = threading.Event()
    previous = {sig: signal.signal(sig, lambda *_: stop.set()) for sig in (signal.SIGINT, signal.SIGTERM)}
    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
    try:
        node = make()
        # the models and message types built: nothing of theirs to collect, so the collector's full
        # passes (several ms over Pinocchio's and rclpy's objects) leave the servo path alone
        gc.collect()
        gc.freeze()
        executor = SingleThreadedExecutor()
        executor.add_node(node)
        target = executor.spin if loop is None else (lambda: loop(executor, stop))
        worker = threading.Thread(target=target, name="phantom_pin executor", daemon=True)
        worker.start()
        node.get_logger().info(ready)
        try:
            while not stop.wait(0.1) and worker.is_alive():
                pass
        finally:
            stop.set()
            if loop is not None:   # it returns once stop is set: let it finish before the executor goes (a
                worker.join(timeout=5.0)   # shutdown inside its spin_once raised InvalidHandle there, under load)
            executor.shutdown(timeout_sec=5.0)
            worker.join(timeout=5.0)
            node.destroy_node()
    finally:
        rclpy.try_shutdown()
        for sig, handler in previous.items():
            signal.signal(sig, handler)
    return 0
