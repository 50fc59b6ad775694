"""The ROS 2 node (phantom_pin.interfaces.ros2.node, `phantom-pin ros2`): its computation against the closed form,
the gimbal's rigid-body reference and the URDF's mimic semantics written here; then the real
node over loopback with the real rclpy (PyPI's wheels): a driver's joint_states replayed at
1 kHz for 2 s, every message it publishes checked, counted and timed, bad messages dropped
with a warning, and a clean stop on SIGINT and SIGTERM."""

from __future__ import annotations

import signal
import subprocess
import sys
import time

import numpy as np
import pytest
import yaml

from helpers import CONFIG_DIR, in_process
from helpers import ros_environment as _environment
from helpers import stop_process as _stop
from phantom_pin import InvalidInputError, Phantom, closed_form
from phantom_pin.config import read
from phantom_pin.interfaces import conventions
from phantom_pin.interfaces.ros2 import node as ros2
from phantom_pin.interfaces.ros2.node import Bridge
from references.gimbal import gimbal_gravity, openhaptics, ubitrack

TOUCH = CONFIG_DIR.parent / "touch"
KINEMATICS = yaml.safe_load((TOUCH / "kinematics.yaml").read_text())
GIMBAL = yaml.safe_load((TOUCH / "gimbal.yaml").read_text())
LIMITS = yaml.safe_load((TOUCH / "joint_limits.yaml").read_text())["stops"]
DRIVER = ("waist", "shoulder", "elbow", "yaw", "pitch", "roll")


@pytest.fixture(scope="module")
def touch() -> Phantom:
    return Phantom.from_model("touch")


def driver_states(n: int, seed: int) -> np.ndarray:
    """``n`` seeded joint_states positions in the drivers' convention (waist, shoulder, elbow =
    theta3 - theta2, raw gimbal), inside the Touch's stops and gimbal ranges (its YAML)."""
    rng = np.random.default_rng(seed)
    joints = ("joint1", "joint2", "joint3")
    theta = rng.uniform([LIMITS[j]["lower"] for j in joints], [LIMITS[j]["upper"] for j in joints], (8 * n, 3))
    keep = ((theta[:, 1] - theta[:, 2] <= LIMITS["theta2_minus_theta3_max"])
            & (theta[:, 2] - theta[:, 1] <= LIMITS["theta3_minus_theta2_max"]))
    theta = theta[keep][:n]
    ranges = GIMBAL["joints"]
    g = rng.uniform([ranges[j]["lower"] for j in ("joint4", "joint5", "joint6")],
                    [ranges[j]["upper"] for j in ("joint4", "joint5", "joint6")], (n, 3))
    return np.column_stack([theta[:, 0], theta[:, 1], theta[:, 2] - theta[:, 1], g])


def base_from_s() -> np.ndarray:
    """report_s in base_link (the macro's frame: at (l1, 0, -l2), the report's x, y, z along
    base_link's y, z, x)."""
    out = np.eye(4)
    out[:3, :3] = [[0, 0, 1], [1, 0, 0], [0, 1, 0]]
    out[:3, 3] = KINEMATICS["l1"], 0, -KINEMATICS["l2"]
    return out


def expected(report, position: np.ndarray) -> dict:
    """What the node must publish for one drivers' message, from the closed form (eqs 10, 93-94),
    the gimbal's reference load and Ubitrack's stylus rotation, and the URDF's mimic tags."""
    waist, shoulder, elbow, *g = position
    theta, g = np.array([waist, shoulder, shoulder + elbow]), np.array(g)
    tau = closed_form.gravity(theta, report) + gimbal_gravity(theta, g)
    tip = base_from_s() @ closed_form.forward_kinematics(theta, report)
    position_s, rotation = ubitrack(openhaptics(theta, g))
    stylus = np.eye(4)
    stylus[:3, :3], stylus[:3, 3] = rotation, position_s - GIMBAL["tip_offset"] * rotation[:, 2]
    model = {"joint1": theta[0], "joint2": theta[1], "joint3": theta[2], "crank_pin_a": -theta[2],
             "crank_pin_b": theta[1], "forearm_pin_a": -theta[1], "forearm_pin_b": theta[2],
             "joint4": g[0], "joint5": g[1], "joint6": g[2]}
    return {"effort": np.array([tau[0], tau[1] + tau[2], tau[2]]),
            "openhaptics": 1000 * np.array([-tau[0], tau[1], tau[2]]),
            "tip": tip, "stylus": base_from_s() @ stylus, "model": model}


def test_the_bridge_gives_the_closed_forms_torques_and_poses(touch):
    """The drivers' six names, shuffled among others: effort conjugate to the drivers'
    coordinates, OpenHaptics' mN m, the tip and the stylus tip in base_link, every URDF joint:
    1e-12 (N m, mN m to 1e-9, m)."""
    bridge = Bridge(touch)
    names = ["roll", "extra", "elbow", "waist", "yaw", "shoulder", "pitch"]
    for position in driver_states(100, seed=1):
        values = dict(zip(DRIVER, position))
        out = bridge(names, [values.get(n, 7.0) for n in names])
        reference = expected(touch.config.report, position)
        assert out.names == ("waist", "shoulder", "elbow")
        assert np.abs(out.effort - reference["effort"]).max() < 1e-12
        assert np.abs(out.openhaptics - reference["openhaptics"]).max() < 1e-9
        assert np.abs(out.tip - reference["tip"]).max() < 1e-12
        assert np.abs(out.stylus - reference["stylus"]).max() < 1e-12
        assert dict(zip(out.model_names, out.model_positions)) == pytest.approx(reference["model"], abs=1e-15)


def test_the_bridge_takes_the_models_names_and_a_prefix(touch):  # noqa: ARG001
    """joint1..joint6 with a prefix: the torques are the report's tau themselves."""
    from phantom_pin import describe

    bridge = Bridge(Phantom(describe("touch", prefix="left_")))
    position = driver_states(1, seed=2)[0]
    theta = [position[0], position[1], position[1] + position[2]]
    out = bridge([f"left_joint{k}" for k in range(1, 7)], [*theta, *position[3:]])
    tau = closed_form.gravity(np.array(theta), touch.config.report) + gimbal_gravity(np.array(theta), position[3:])
    assert out.names == ("left_joint1", "left_joint2", "left_joint3") and np.abs(out.effort - tau).max() < 1e-12


@pytest.mark.parametrize("names, position, field", [
    (["waist", "shoulder"], [0.1, 0.2], "name"),
    (list(DRIVER), [0.1, 0.2, 0.3], "position"),
    (list(DRIVER), [0.1, float("nan"), 0.3, 0, 0, 0], "position"),
    (list(DRIVER), [0.1, 0.2, 0.3, 0, 12.0, 0], "position"),
    (list(DRIVER), [-9.0, 0.2, 0.3, 0, 0, 0], "position"),
])
def test_a_bad_message_is_refused_naming_its_field(touch, names, position, field):
    with pytest.raises(InvalidInputError) as error:
        Bridge(touch)(names, position)
    assert error.value.argument == field


# -- the real node over loopback ------------------------------------------------------------------

RATE, SECONDS = 1000.0, 2.0




def _start_node() -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "phantom_pin.cli", "--model", "touch", "ros2"],
                            env=_environment(), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


@pytest.mark.slow
def test_the_node_answers_a_1khz_driver_stream_over_loopback(touch):
    """2000 drivers' messages at 1 kHz: each answered on every topic with its stamp and frame,
    equal to the closed form (1e-12), the share left unanswered printed (the node keeps the
    newest 10 when it falls behind); a bad message dropped with one warning naming its
    field, the node still answering; SIGTERM stops it cleanly. The node's latency per message
    (when it published its answer minus the input's stamp, both the system clock) printed."""
    in_process(_environment())
    import rclpy
    from geometry_msgs.msg import PoseStamped
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.qos import QoSProfile, ReliabilityPolicy
    from sensor_msgs.msg import JointState

    process = _start_node()
    context = rclpy.Context()
    rclpy.init(context=context)
    try:
        node = rclpy.create_node("driver_replay", context=context)
        executor = SingleThreadedExecutor(context=context)
        executor.add_node(node)
        qos = QoSProfile(depth=5000, reliability=ReliabilityPolicy.RELIABLE)
        publisher = node.create_publisher(JointState, "joint_states", qos)
        received: dict[str, list] = {t: [] for t in ("gravity_torque", "gravity_torque_openhaptics", "tip_pose",
                                                       "stylus_pose", "model_joint_states")}
        clock = node.get_clock()
        for topic, kind in (("gravity_torque", JointState), ("gravity_torque_openhaptics", JointState),
                            ("tip_pose", PoseStamped), ("stylus_pose", PoseStamped),
                            ("model_joint_states", JointState)):
            # the message info's source timestamp: when the node published it (ns, the system clock)
            node.create_subscription(kind, topic, lambda m, info, t=topic: received[t].append(
                (m, info["source_timestamp"])), qos)
        deadline = time.monotonic() + 30
        while publisher.get_subscription_count() < 1 or any(
                node.count_publishers(t) < 1 for t in received):
            assert process.poll() is None, process.communicate()[1]
            assert time.monotonic() < deadline, "the node did not appear on the loopback within 30 s"
            executor.spin_once(timeout_sec=0.05)
        time.sleep(0.5)  # discovery completes both ways
        states = driver_states(int(RATE * SECONDS), seed=3)
        start = time.monotonic()
        for k, position in enumerate(states):
            message = JointState()
            message.header.stamp = clock.now().to_msg()
            message.header.frame_id = f"{k}"
            message.name, message.position = list(DRIVER), [float(v) for v in position]
            publisher.publish(message)
            while time.monotonic() < start + (k + 1) / RATE:
                executor.spin_once(timeout_sec=0)
        # the answers still coming: until all came, none came for 0.5 s (the node drops stale
        # messages when it falls behind, so some never come), or 5 s passed
        end, quiet, count = time.monotonic() + 5, time.monotonic() + 0.5, -1
        while time.monotonic() < min(end, quiet) and min(len(v) for v in received.values()) < len(states):
            executor.spin_once(timeout_sec=0.01)
            if sum(len(v) for v in received.values()) != count:
                count, quiet = sum(len(v) for v in received.values()), time.monotonic() + 0.5
        counts = {t: len(v) for t, v in received.items()}
        answered = counts["tip_pose"]
        print(f"\nros2 node: {len(states)} messages at {RATE:.0f} Hz; answered {answered} "
              f"({100 * (1 - answered / len(states)):.1f} % left unanswered: stale when the node falls behind)")
        # every message answered is answered on all five topics; a node far too slow (or dead) fails
        assert len(set(counts.values())) == 1 and answered >= len(states) // 4, counts
        latencies = []
        report = touch.config.report
        for k, ((effort, at), (hd, _), (tip, _), (stylus, _), (full, _)) in enumerate(zip(*received.values())):
            index = int(effort.header.frame_id)
            stamp = effort.header.stamp
            assert all(m.header.stamp == stamp for m in (hd, tip, stylus, full))
            assert tip.header.frame_id == stylus.header.frame_id == "base_link"
            latencies.append((at - (stamp.sec * 10**9 + stamp.nanosec)) * 1e-9)
            if k % 10:
                continue  # the reference is slow in Python: every tenth message
            reference = expected(report, states[index])
            assert list(effort.name) == ["waist", "shoulder", "elbow"]
            assert np.abs(np.array(effort.effort) - reference["effort"]).max() < 1e-12
            assert np.abs(np.array(hd.effort) - reference["openhaptics"]).max() < 1e-9
            for pose, want in ((tip, reference["tip"]), (stylus, reference["stylus"])):
                p, q = pose.pose.position, pose.pose.orientation
                assert np.abs(np.array([p.x, p.y, p.z]) - want[:3, 3]).max() < 1e-12
                w, x, y, z = q.w, q.x, q.y, q.z
                rotation = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
                assert np.abs(rotation - want[:3, :3]).max() < 1e-12
            assert dict(zip(full.name, full.position)) == pytest.approx(reference["model"], abs=1e-15)
        median, p99 = np.percentile(latencies, [50, 99]) * 1e3
        first = received["tip_pose"][0][0].header.stamp
        span = (received["tip_pose"][-1][1] - (first.sec * 10**9 + first.nanosec)) * 1e-9
        print(f"ros2 node latency per message: median {median:.2f} ms, 99th percentile {p99:.2f} ms; "
              f"{answered / span:.0f} messages answered per second")
        # bad messages: dropped, one warning naming the field, the node still answers
        before = len(received["tip_pose"])
        for bad in ([0.1, float("nan"), 0.3, 0, 0, 0], [0.1, 0.2]):
            message = JointState()
            message.name, message.position = list(DRIVER), bad
            publisher.publish(message)
        good = JointState()
        good.header.stamp = clock.now().to_msg()
        good.name, good.position = list(DRIVER), [float(v) for v in states[0]]
        publisher.publish(good)
        end = time.monotonic() + 5
        while time.monotonic() < end and len(received["tip_pose"]) < before + 1:
            executor.spin_once(timeout_sec=0.01)
        assert len(received["tip_pose"]) == before + 1 and process.poll() is None
    finally:
        rclpy.try_shutdown(context=context)
        code, err = _stop(process, signal.SIGTERM)
    warnings = [line for line in err.splitlines() if "dropped a joint_states message" in line]
    assert len(warnings) == 1 and "position" in warnings[0], err  # throttled: one per second
    assert code == 0, err


def _wait_ready(process: subprocess.Popen, timeout: float = 60.0) -> None:
    """Read the node's log until it says it spins (its model built, rclpy up)."""
    import selectors

    selector = selectors.DefaultSelector()
    selector.register(process.stderr, selectors.EVENT_READ)
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if selector.select(timeout=0.5) and "joint_states -> gravity" in process.stderr.readline():
            return
        assert process.poll() is None, process.communicate()[1]
    raise AssertionError("the node did not start within 60 s")


def test_the_node_stops_cleanly_on_sigint_and_refuses_bad_arguments_in_one_line():
    process = _start_node()
    _wait_ready(process)
    code, err = _stop(process, signal.SIGINT)
    assert code == 0 and "Traceback" not in err, err
    result = subprocess.run([sys.executable, "-m", "phantom_pin.cli", "ros2", "--topic", "bogus=x"],
                            env=_environment(), capture_output=True, text=True, timeout=60)
    assert result.returncode == 2 and len(result.stderr.strip().splitlines()) == 1, result.stderr
    assert "--topic" in result.stderr


# -- Bridge: names given twice, the gimbal's names, the velocity, a model without a gimbal -------


@pytest.mark.parametrize("names", [
    ["waist", "waist", "shoulder", "elbow"],
    ["waist", "shoulder", "elbow", "yaw", "pitch", "roll", "pitch"],
    ["joint1", "joint2", "joint3", "joint3"],
    ["joint1", "joint2", "joint3", "joint4", "joint5", "joint6", "joint4"],
])
def test_a_name_given_twice_is_refused_as_the_drivers_conversions_refuse_it(touch, names):
    """The node drops a message giving a joint name twice, InvalidInputError naming ``name``, as
    conventions.theta_from_joint_state and gimbal_from_joint_state refuse it, naming ``names``."""
    position = [0.1] * len(names)
    with pytest.raises(InvalidInputError) as error:
        ros2.Bridge(touch)(names, position)
    assert error.value.argument == "name"
    if names[0] == "waist":
        convert = conventions.theta_from_joint_state if len(names) == 4 else conventions.gimbal_from_joint_state
        with pytest.raises(InvalidInputError) as error:
            convert(names, position)
        assert error.value.argument == "names"


@pytest.mark.parametrize("gimbal_names", [("joint4", "joint5", "joint6"), ("yaw", "pitch", "roll")])
@pytest.mark.parametrize("arm_names", ["driver", "model"])
def test_the_gimbal_is_read_under_either_names_with_either_arm(touch, arm_names, gimbal_names):
    """The node reads the gimbal under the drivers' names (yaw, pitch, roll) or the model's
    (joint4..joint6), beside either the drivers' arm names or the model's: each pairing gives the
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
    """A message with some but not all of the gimbal's names, or the gimbal under both sets of
    names, is refused with InvalidInputError naming ``name`` (never an exception the node does
    not catch)."""
    with pytest.raises(InvalidInputError) as error:
        ros2.Bridge(touch)(names, [0.1] * len(names))
    assert error.value.argument == "name"


def test_a_velocity_of_the_wrong_length_is_refused(touch):
    """A velocity field has one value per name, or none (the drivers that publish no velocity);
    another length is refused naming ``velocity``."""
    names, position = list(DRIVER), list(driver_states(1, seed=12)[0])
    bridge = ros2.Bridge(touch)
    for velocity in ([0.0, 0.1], [0.0] * 7):
        with pytest.raises(InvalidInputError) as error:
            bridge(names, position, velocity)
        assert error.value.argument == "velocity"
    assert np.array_equal(bridge(names, position, [0.5] * 6).effort, bridge(names, position).effort)


def test_the_bridge_of_a_model_without_a_gimbal_answers_from_the_closed_form():
    """The Bridge of a model without a gimbal (premium_1_5) answers from the closed form: against
    the report's closed form (eqs 10, 93-94) and the URDF's mimic tags written out here, under the
    drivers' names (their yaw, pitch, roll ignored, there being no gimbal) and the model's, 1e-12
    (N m, m)."""
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
    """The OpenHaptics topic names its torques turret, thigh, shin (after the prefix), each
    carrying its own joint's torque. OpenHaptics' reference guide names its joints "Turet Left +,
    Thigh Up +, Shin Up +", in the order of HD_CURRENT_JOINT_ANGLES; its torque on each is 1000
    (-tau1, tau2, tau3) mN m (SensAble's CommandJointTorque sample), tau the closed form's."""
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


# -- the force path's message handling without a network (mutation survivors of mutants6.md) -------
class _Node:
    """What _on_wrench and _send_force use of the node: its user force, a force publisher that
    keeps what it is given, a logger."""

    def __init__(self) -> None:
        import types

        self.user = ("", (0.0, 0.0, 0.0))
        self.sent: list = []
        self.force = types.SimpleNamespace(publish=self.sent.append)
        self.warned: set[str] = set()
        logger = types.SimpleNamespace(warning=lambda *a, **k: None)
        self.get_logger = lambda: logger


def _stamp(seconds: float):
    from builtin_interfaces.msg import Time

    return Time(sec=int(seconds), nanosec=int(round((seconds - int(seconds)) * 1e9)))


@pytest.mark.parametrize("name", ["sawsensablephantom", "touch_ros2_control", "phantom_touch_ros2"])
def test_a_users_wrench_in_base_link_reaches_the_driver_as_the_same_force_and_the_command_its_stamp(touch, name):
    """Mutants 24 and 26. A user's WrenchStamped (0.1, -0.2, 0.3) N in base_link through
    ros2._on_wrench, then the force command of a state through ros2._send_force: the driver's own
    formula of the message it gets (driver_reference.FORCE) gives J^T F = G + J^T (R F_user),
    R base_link's axes in frame s (driver_reference.BASE_FROM_S, the macro's frame), J and G the
    references' (1e-9 N m); a stamped type carries the state's stamp (a driver that checks
    stamps needs it), exactly."""
    from geometry_msgs.msg import WrenchStamped

    from phantom_pin.interfaces import profiles
    from references import driver as ref

    profile = profiles.load(name)
    driver = ros2.DriverBridge(touch, profile)
    node, kind = _Node(), ros2.message_type(profile.force.type)
    wrench = WrenchStamped()
    wrench.header.frame_id = "base_link"
    wrench.wrench.force.x, wrench.wrench.force.y, wrench.wrench.force.z = 0.1, -0.2, 0.3
    ros2._on_wrench(node, driver, wrench)
    theta, g = ref.states(5, seed=31)
    for k, (t, gg) in enumerate(zip(theta, g)):
        stamp = _stamp(1000.0 + 0.25 * k)
        ros2._send_force(node, driver, kind, t, gg, stamp)
        command = node.sent[-1]
        got = ref.FORCE[name](command)
        f_s = ref.BASE_FROM_S.T @ np.array([0.1, -0.2, 0.3])
        want = ref.gravity(t, gg, touch.config.report) + ref.tip_jacobian(t).T @ f_s
        assert np.abs(ref.tip_jacobian(t).T @ got - want).max() < 1e-9
        if profile.force.header:
            assert (command.header.stamp.sec, command.header.stamp.nanosec) == (stamp.sec, stamp.nanosec)


def test_friction_compensation_runs_on_the_states_stamps_when_they_arrive_in_a_burst(touch):
    """Mutant 21. 400 states of a joint path at a constant rate w (rad/s), stamped 1 ms apart but
    handed to ros2._send_force at once (a burst, as a busy executor delivers them): the rate is
    the stamps' (the wall clock's would be microseconds apart), so after them J^T F = G +
    viscous w + Coulomb sign(w) (config/touch/actuation.yaml: 5e-4 N m s/rad, 0.01 N m; the
    references' J and G), 1e-9 N m."""
    from phantom_pin.interfaces import profiles
    from references import driver as ref

    profile = profiles.load("geomagic_touch_x_ros2")
    driver = ros2.DriverBridge(touch, profile, compensate=("gravity", "friction"))
    node, kind = _Node(), ros2.message_type(profile.force.type)
    rate, start, gimbal = np.array([0.4, -0.3, 0.2]), np.array([0.0, 0.4, 0.5]), np.zeros(3)
    for k in range(401):
        t = start + rate * k * 1e-3
        ros2._send_force(node, driver, kind, t, gimbal, _stamp(2000.0 + k * 1e-3))
    got = ref.FORCE["geomagic_touch_x_ros2"](node.sent[-1])
    want = ref.gravity(t, gimbal, touch.config.report) + 5e-4 * rate + 0.01 * np.sign(rate)
    assert np.abs(ref.tip_jacobian(t).T @ got - want).max() < 1e-9


def test_with_a_driver_the_outputs_follow_at_a_hundred_hertz(touch, monkeypatch):
    """Mutant 25. A 1 kHz driver's states for 1 s of the node's monotonic clock (a fake clock, 1 ms a
    state; no network: the node is built, not spun, and its outputs counted as listened to):
    the gravity torques, poses and model joint states follow at most at 100 Hz (ros2.OUTPUTS_RATE,
    docs/ros2.md) and no less than at 90 Hz: 10 or 11 ms apart (the next due time, 10 ms after the
    last, falls between two states of the millisecond grid or on one, by the clock's rounding;
    95 here), and every state gets its force."""
    import types

    import rclpy

    from phantom_pin.interfaces import profiles

    in_process(_environment())
    clock = types.SimpleNamespace(now=0.0)
    monkeypatch.setattr(ros2, "time", types.SimpleNamespace(monotonic=lambda: clock.now, time=time.time))
    context_was_up = rclpy.ok()
    if not context_was_up:
        rclpy.init()
    try:
        driver = ros2.DriverBridge(touch, profiles.load("geomagic_touch_x_ros2"))
        node = ros2.make_node(touch, driver=driver)
        sent: list = []
        node.force = types.SimpleNamespace(publish=sent.append)
        node.outputs = {role: types.SimpleNamespace(get_subscription_count=lambda: 1) for role in node.outputs}
        theta, gimbal = np.array([0.1, 0.4, 0.5]), np.zeros(3)
        answered = []
        for k in range(1000):
            clock.now = 100.0 + k * 1e-3
            if node.serve((theta, gimbal), _stamp(5.0 + k * 1e-3)) is not None:
                answered.append(k)
        node.destroy_node()
    finally:
        if not context_was_up:
            rclpy.shutdown()
    assert len(sent) == 1000
    assert 90 <= len(answered) <= 100 and set(np.diff(answered)) <= {10, 11}, answered[:5]
