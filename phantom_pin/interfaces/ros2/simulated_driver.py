"""A simulated driver: the device's own plant under a public driver's force command, in real
time over ROS 2, so that users (and the tests) develop against a driver without hardware.

``DriverSimulation`` is the computation without ROS: each servo tick (1 ms) it turns the last
force command into the force OpenHaptics renders, as the profile's driver does (its frame A,
its damping and start-up spring, its NaN handling, its norm clamp, the command held or applied
for one tick: phantom_pin.interfaces.profiles), applies J_p(theta)^T F at the gimbal centre to the plant
(Device's gravity, friction, stops and saturation; device.plant), and gives the joint states in
the driver's conventions. No hand holds the stylus, except that ``hold`` keeps it at theta0 for
its first seconds, as a user's hand would until a node started alongside connects (``release()``
lets go sooner: the command-line driver calls it on SIGUSR1).

``make_node`` and ``spin`` put it on ROS 2: the profile's joint-state topic at its rate and
quality of service (positions, rad, in its conventions; efforts, where the driver publishes
OpenHaptics' joint torques, the motors' J_p^T F in mN m on OpenHaptics' angles), and its force
topic in its message type. A command counts from the first servo tick at or after its arrival in
the middleware, as the driver's own ROS thread takes it, however late the loop here runs; at the
end the log says for how many ticks after the release a command arrived.
"""

from __future__ import annotations

import math
import signal
import threading
import time
from collections.abc import Sequence
from typing import Any

import numpy as np
import pinocchio as pin

from phantom_pin.device.device import Device
from phantom_pin.device.plant import servo_plant
from phantom_pin.exceptions import InvalidInputError
from phantom_pin.interfaces import conventions
from phantom_pin.interfaces.profiles import Profile, StateTopic
from phantom_pin.interfaces.ros2.node import _qos, message_type, run

__all__ = ["DriverSimulation", "make_node", "loop", "spin"]

#: The servo loop's period (s): OpenHaptics' 1 kHz.
PERIOD = 1e-3
#: What the node logs when the first force command reaches it (the loopback tests wait for it).
FIRST_COMMAND = "first force command received"
#: The most servo ticks one pass of the real-time loop catches up (a machine too busy to keep
#: up drops the rest: the simulated time then lags the clock, said once in the log).
CATCH_UP = 20


class DriverSimulation:
    """The device under a driver (module doc). ``device``: its Device (its Phantom's gimbal
    locked at the angles the stylus is held at); ``profile``; ``theta0`` (rad, inside the
    stops); ``hold`` (s, >= 0). ``tick()`` advances one servo period; ``command(numbers)``
    takes a force message's three numbers (N, the driver's frame)."""

    def __init__(self, device: Device, profile: Profile, theta0: Sequence[float], hold: float = 0.0) -> None:
        theta = np.array(theta0, dtype=float)
        if theta.shape != (3,) or not np.isfinite(theta).all() or not device.within_limits(theta):
            raise InvalidInputError(f"expected three angles (rad) inside the stops, got {theta0!r}", argument="theta0")
        if isinstance(hold, bool) or not isinstance(hold, (int, float)) or not 0 <= hold < math.inf:
            raise InvalidInputError(f"expected a time >= 0 s, got {hold!r}", argument="hold")
        self.device, self.profile, self.hold = device, profile, float(hold)
        self.plant, self.steps = servo_plant(device, theta, PERIOD)
        self.q, self.v = theta.tolist(), [0.0, 0.0, 0.0]
        self.x0 = device.phantom.forward_kinematics(theta)[:3, 3]     # m, frame s: the spring's target
        self.time = 0.0                                                 # s, simulated
        self.message: np.ndarray | None = None                          # the last command's numbers
        self.fresh = False
        self.pending: list[tuple[float, np.ndarray]] = []               # (arrival s, numbers) not yet due
        self.applied = np.zeros(3)                                      # N m, J^T F of the last tick
        self.ticks = self.commanded = 0                                 # ticks after hold; of them, with a command

    def command(self, numbers: Sequence[float], at: float | None = None) -> None:
        """A force message's three numbers (N, the driver's frame), as the driver receives them:
        at once, or, given ``at`` (when it arrived, s, the clock of tick's ``at``), in the first
        tick at or after that time."""
        values = np.array([float(v) for v in numbers])
        if at is None:
            self.message, self.fresh = values, True
        else:
            self.pending.append((float(at), values))

    def _arrived(self, at: float) -> None:
        """The commands arrived by ``at`` (s) are the driver's: the latest its message (the driver's
        callback ran for each, as its ROS thread does, independent of the servo thread)."""
        due = [(t, m) for t, m in self.pending if t <= at]
        if due:
            self.message, self.fresh = max(due, key=lambda item: item[0])[1], True
            self.pending = [(t, m) for t, m in self.pending if t > at]

    def force(self, jacobian: np.ndarray) -> np.ndarray:
        """HD_CURRENT_FORCE this tick (N, OH = frame s), as the profile's driver computes it."""
        spec = self.profile.force
        if self.message is None or (spec.hold == "one_tick" and not self.fresh):
            force = np.zeros(3)
        else:
            force = spec.to_openhaptics @ self.message
        if spec.damping:
            force = force - spec.damping * (jacobian @ np.array(self.v))
        if spec.spring:
            force = force + spec.spring * (self.x0 - self.device.phantom.forward_kinematics(np.array(self.q))[:3, 3])
        if spec.nan_to_zero:
            force = np.where(np.isfinite(force), force, 0.0)
        elif not np.isfinite(force).all():
            force = np.zeros(3)   # what the hardware does with NaN is not public: no force
        norm = float(np.linalg.norm(force))
        return force * (spec.clamp / norm) if norm > spec.clamp else force

    def tick(self, at: float | None = None) -> None:
        """One servo period: the driver's force as joint torques on the plant (after ``hold``);
        ``at`` (s): the tick's time on the clock of command's ``at``, which takes the commands
        arrived by then."""
        if at is not None:
            self._arrived(at)
        theta = np.array(self.q)
        jacobian = self.device.tip_jacobian(theta)
        self.applied = jacobian.T @ self.force(jacobian)
        if self.time >= self.hold:
            self.ticks += 1
            self.commanded += self.fresh
            self.q, self.v = self.plant.hold(self.q, self.v, self.applied.tolist(), PERIOD, self.steps)
        self.fresh = False
        self.time += PERIOD

    def release(self) -> None:
        """Let the stylus go at the end of the next servo tick, however long ``hold`` has left
        (nothing if it was let go already)."""
        self.hold = min(self.hold, self.time + PERIOD)

    def joint_state(self, gimbal: Sequence[float]) -> tuple[list[str], list[float], list[float]]:
        """(names, positions (rad), efforts) of the driver's joint_states: the arm and the stylus
        gimbal (raw angles ``gimbal``, rad) in its conventions; efforts in mN m where it publishes
        OpenHaptics' joint torques (the motors' J^T F, the gimbal's 0), else empty."""
        positions = [*self.profile.state_from_arm(self.q), *self.profile.state_from_gimbal(gimbal)]
        efforts: list[float] = []
        if self.profile.joint_states.effort_unit == "mN m":
            efforts = [*conventions.openhaptics_torque_from_tau(self.applied).tolist(), 0.0, 0.0, 0.0]
        return list(self.profile.joint_states.names), [float(p) for p in positions], efforts


    def state_topics(self, gimbal: Sequence[float]) -> list[tuple[StateTopic, np.ndarray, np.ndarray]]:
        """The profile's state topics now: (topic, position m or linear velocity m/s, rotation
        (3, 3) or angular velocity rad/s), in the driver's axes. OpenHaptics' HD_CURRENT_TRANSFORM
        of the stylus (conventions.openhaptics_transform_from_pose: its origin an ESTIMATE), its
        velocity J_p dtheta and the stylus's angular velocity (Phantom.stylus_jacobian), the
        gimbal held still."""
        phantom, theta, g = self.device.phantom, np.array(self.q), np.asarray(gimbal, dtype=float)
        out = []
        for spec in self.profile.state_topics:
            if spec.type.endswith("PoseStamped"):
                flat = conventions.openhaptics_transform_from_pose(phantom.stylus_pose(theta, g),
                                                               conventions.openhaptics_origin(phantom))
                transform = flat.reshape(4, 4).T                              # column-major, mm
                turned = spec.rotation_axes
                out.append((spec, spec.axes @ transform[:3, 3] * conventions.METRE_PER_MM,
                            turned @ transform[:3, :3] @ turned.T @ spec.after))
            else:
                rates = np.concatenate([self.v, np.zeros(3)])
                angular = (phantom.stylus_jacobian(theta, g) @ rates)[3:]
                linear = self.device.tip_jacobian(theta) @ np.array(self.v)
                out.append((spec, spec.axes @ linear, spec.axes @ angular))
        return out


def make_node(simulation: DriverSimulation, gimbal: Sequence[float], prefix: str = "", name: str = "sim_driver"):
    """The rclpy node of a DriverSimulation (rclpy.init must have run): the profile's force topic
    in, its joint states out (``loop`` runs it in real time)."""
    from rclpy.node import Node
    from sensor_msgs.msg import JointState

    profile = simulation.profile
    force_type = message_type(profile.force.type)
    field = profile.force.field

    class SimulatedDriverNode(Node):
        def __init__(self) -> None:
            super().__init__(name)
            self.states = self.create_publisher(JointState, profile.joint_states.topic, _qos(profile.joint_states.qos))
            qos = _qos(profile.joint_states.qos)
            self.others: list[Any] = [self.create_publisher(message_type(spec.type), spec.topic, qos)
                                      for spec in profile.state_topics]
            self.create_subscription(force_type, profile.force.topic, self.on_force, _qos(profile.force.qos))
            self.received = 0
            self.offset = time.time() - time.monotonic()   # s: the system clock's reading less the loop's

        def on_force(self, message, info) -> None:
            vector = message
            for part in (field or "").split("."):
                vector = getattr(vector, part) if part else vector
            # when it arrived (the middleware's time, on the system clock), not when this callback ran: the
            # driver's ROS thread takes each message then, whatever the servo loop here is doing
            simulation.command((vector.x, vector.y, vector.z), at=info["received_timestamp"] * 1e-9 - self.offset)
            if not self.received:   # a test lets the stylus go only once the driver has a command
                self.get_logger().info(FIRST_COMMAND)
            self.received += 1

        def publish_state(self) -> None:
            names, positions, efforts = simulation.joint_state(gimbal)
            message = JointState()
            message.header.stamp = self.get_clock().now().to_msg()
            message.name, message.position, message.effort = [prefix + n for n in names], positions, efforts
            self.states.publish(message)
            for publisher, (spec, first, second) in zip(self.others, simulation.state_topics(gimbal)):
                other = message_type(spec.type)()
                other.header.stamp, other.header.frame_id = message.header.stamp, prefix + spec.frame_id
                if spec.type.endswith("PoseStamped"):
                    _pose(other, first, second)
                else:
                    _twist(other, first, second)
                publisher.publish(other)

    return SimulatedDriverNode()


def _pose(message, position: np.ndarray, rotation: np.ndarray) -> None:
    p, o = message.pose.position, message.pose.orientation
    p.x, p.y, p.z = (float(v) for v in position)
    q = pin.Quaternion(rotation)
    o.x, o.y, o.z, o.w = float(q.x), float(q.y), float(q.z), float(q.w)


def _twist(message, linear: np.ndarray, angular: np.ndarray) -> None:
    message.twist.linear.x, message.twist.linear.y, message.twist.linear.z = (float(v) for v in linear)
    message.twist.angular.x, message.twist.angular.y, message.twist.angular.z = (float(v) for v in angular)


def loop(simulation: DriverSimulation, node, executor, stop: threading.Event) -> None:
    """Real time: the servo ticks due by the clock, the joint states at the profile's rate, and
    the executor's callbacks (force commands) between them, until ``stop``."""
    rate_period = 1.0 / simulation.profile.joint_states.rate
    start, ticks, published, lagging, late = time.monotonic(), 0, 0, False, 0
    while not stop.is_set():
        received = -1
        while received != node.received:   # the commands waiting, before the ticks that may be due
            received = node.received
            executor.spin_once(timeout_sec=0.0)
        due = int((time.monotonic() - start) / PERIOD)
        if due - ticks > CATCH_UP:
            if not lagging:
                node.get_logger().warning(f"the machine is too busy for real time: dropped {due - ticks - CATCH_UP} "
                                          "servo ticks (the simulated time lags the clock)")
                lagging = True
            start += (due - ticks - CATCH_UP) * PERIOD
            due = ticks + CATCH_UP
        while ticks < due:
            held = simulation.time < simulation.hold
            at = start + (ticks + 1) * PERIOD
            simulation.tick(at=at)
            ticks += 1
            late += simulation.time > simulation.hold and time.monotonic() > at + PERIOD
            if held and simulation.time >= simulation.hold:
                node.get_logger().info(f"released: the stylus is let go after {simulation.hold:g} s")
            if ticks * PERIOD >= published * rate_period:
                node.publish_state()
                published += 1
        executor.spin_once(timeout_sec=max(0.0, start + (ticks + 1) * PERIOD - time.monotonic()))
    node.get_logger().info(f"a command arrived for {simulation.commanded} of the {simulation.ticks} servo ticks "
                           f"after the release ({node.received} commands in all); {late} ticks ran more than a period "
                           "late")


def spin(simulation: DriverSimulation, gimbal: Sequence[float], prefix: str = "") -> int:
    """Run the simulated driver until SIGINT or SIGTERM; 0 on a clean stop. SIGUSR1 lets the
    stylus go (``DriverSimulation.release``) where ``hold`` still holds it."""
    nodes: list = []
    previous = signal.signal(signal.SIGUSR1, lambda *_: simulation.release())

    def make():
        nodes.append(make_node(simulation, gimbal, prefix))
        return nodes[0]

    profile = simulation.profile
    try:
        return run(make, f"sim-driver {profile.name}: {profile.force.topic} -> {profile.joint_states.topic} at "
                         f"{profile.joint_states.rate:g} Hz", lambda executor, stop: loop(simulation, nodes[0],
                                                                                         executor, stop))
    finally:
        signal.signal(signal.SIGUSR1, previous)
