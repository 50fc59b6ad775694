"""End to end over ROS 2 on loopback, with the real rclpy: for one driver profile per kind of force
message among those whose message types install here (LOOPBACK), the simulated driver (phantom-pin
sim-driver) and the node (phantom-pin ros2 --driver) as two processes. Let go (SIGUSR1) once this
test's own node receives the states and the forces, the stylus floats (within 2 mm for FLOAT s; for
kinisi's one-tick driver only the node's part is asserted, docs/drivers.md); a user's 0.5 N up lifts
it; the force the node publishes, taken back to OpenHaptics' frame by the driver's own formula
(driver_reference), holds the Touch's gravity from the closed form (1e-9 N m); without the node the
stylus falls. omni_msgs (geomagic_touch_ros2) is not on PyPI: the node refuses that profile in one
line, and the documents' one-file relay (`--relay`) is run as printed with a stand-in for omni_msgs."""

from __future__ import annotations

import atexit
import functools
import os
import re
import selectors
import signal
import subprocess
import sys
import time
import types
from pathlib import Path

import numpy as np
import pytest

from helpers import in_process, installed_profiles
from helpers import ros_environment as environment
from helpers import stop_process as stop
from phantom_pin import Phantom, closed_form
from phantom_pin.interfaces import profiles
from phantom_pin.interfaces.ros2.node import message_type
from phantom_pin.interfaces.ros2.simulated_driver import FIRST_COMMAND
from references import driver as ref

INSTALLED = installed_profiles()
THETA0 = np.array([0.2, 0.6, 0.5])   # rad: gravity beats the static friction there (test_sim_driver)
REPORT = Phantom.from_model("touch").config.report
#: The bad wrench each profile's test sends, and the field its warning names.
BAD_WRENCH = {"sawsensablephantom": ("base_link", (float("nan"), 0.0, 0.0), "force"),
              "touch_ros2_control": ("nowhere", (0.0, 0.0, 0.1), "frame_id"),
              "geomagic_touch_x_ros2": ("base_link", (1e9, 0.0, 0.0), "force"),
              "geomagic_touch_ros2": ("stylus", (0.0, -float("inf"), 0.0), "force"),
              "phantom_touch_ros2": ("touch_b_stylus", (0.0, 0.0, 0.1), "frame_id")}
#: s, the most the simulated driver holds the stylus: SIGUSR1 lets it go once this test's watcher
#: has received READY joint states and forces, the forces over READY_SPAN s (ONE_TICK_SPAN s for
#: kinisi's one-tick driver, whose check counts the states the node answers after the release:
#: 100 % in 8 runs at 1 s; ROS discovery takes 1-4 s here).
HOLD = 30.0
READY, READY_SPAN, ONE_TICK_SPAN = 100, 0.5, 1.0
#: s watched after the release: an uncompensated stylus falls 2 mm in 20 ms; a compensated one moves
#: not at all (within 1e-12 m: its static friction holds it), so 0.5 s tells them apart 25 times over.
FLOAT = 0.5
#: The least share of the states after the release that the node answers (forces the watcher
#: receives per state it receives): printed by every run, asserted only so that a node that stopped
#: answering fails; how many a Python executor on 2 shared cores answers is the machine's, not
#: ours (what is ours: every force sent is right, asserted to 1e-9 N m). Measured with both cores
#: busy (two `while 1: pass` processes beside the machine's other users, load 3-10), 50 runs of each
#: loopback test (2026-12-03, DEVELOPERS.md): sawSensablePhantom's 27.8 % at the lowest, kinisi's
#: 45.4 % (79.6 % had failed the 0.8 asserted before), RViMLab's 75.4 %; through the relay (a third
#: process, and the geomagic driver's states come as fast as its executor spins, 1.5-2 kHz) 8.6 %.
ANSWERED_FLOOR, RELAYED_FLOOR = 0.1, 0.03
#: The least share of the forces the geomagic driver receives through the relay that the watcher
#: also saw the node send to the relay (the relay copies them bit for bit; the watcher's
#: best-effort subscription to the relay's topic misses some on a busy machine): 88.9 % at the
#: lowest in the 50 runs above (with "all" asserted, the test that failed now and then).
SEEN_FLOOR = 0.5
#: s, the longest the user's 0.5 N is held waiting for the tip to rise 1 mm (on a busy machine
#: the node may take a burst of wrenches at once: only a force held until it acted is a test of
#: the node, not of the executor's timing).
LIFT_WAIT = 5.0
#: The profiles run over loopback: one per force message type, reliability and hold of the
#: installed ones (test_every_kind_of_force_message_is_run_over_loopback); the others' conventions
#: are checked in process (test_sim_driver, test_forces), their transport is one of these.
LOOPBACK = ("geomagic_touch_x_ros2", "phantom_touch_ros2", "sawsensablephantom")


def _environment() -> dict[str, str]:
    """test_ros2's (loopback, its discovery), in a ROS domain of this module alone (its tests run
    one after another, each stopping its processes before the next starts)."""
    return environment(1 + (os.getpid() + 37) % 100)


@functools.cache
def _context():
    """One rclpy context for the module's watchers: a fresh context per test, each in a domain of
    its own, now and then received nothing from the second test on (FastDDS, in one process)."""
    import rclpy

    context = rclpy.Context()
    rclpy.init(context=context, domain_id=int(_environment()["ROS_DOMAIN_ID"]))
    atexit.register(rclpy.try_shutdown, context=context)
    return context


def _start(env: dict[str, str], *args: str) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "phantom_pin.cli", "--model", "touch", *args], env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def _wait_for(process: subprocess.Popen, text: str, timeout: float = 60.0, watcher=None) -> None:
    """Read ``process``'s log until it says ``text``; spin ``watcher`` meanwhile. The pipe is read
    by its descriptor, all that is in it each time (kept in ``process.seen``): a buffered
    readline() after select() could take two lines and leave select() nothing more to see, and
    the release follows the driver's start-up line by milliseconds."""
    descriptor = process.stderr.fileno()
    selector = selectors.DefaultSelector()
    selector.register(descriptor, selectors.EVENT_READ)
    deadline = time.monotonic() + timeout
    try:
        while time.monotonic() < deadline:
            if selector.select(timeout=0 if watcher else 0.5):
                process.seen = getattr(process, "seen", "") + os.read(descriptor, 1 << 16).decode(errors="replace")
                if text in process.seen:
                    return
            if watcher is not None:
                watcher.spin(0.02)
            assert process.poll() is None, getattr(process, "seen", "") + process.communicate()[1]
    finally:
        selector.close()
    raise AssertionError(f"{process.args} did not say {text!r} within {timeout} s")


def _stop(process: subprocess.Popen) -> tuple[int, str]:
    """SIGTERM, then the exit code and the whole log, what _wait_for read included (test_ros2's,
    which fails on a process that stays)."""
    code, log = stop(process, signal.SIGTERM)
    return code, getattr(process, "seen", "") + log


class Watcher:
    """A test node on the driver's topics: its joint states (theta, rad, by the driver's own
    formulas inverted here) and force commands, with their receipt times; a user's wrench out."""

    def __init__(self, name: str, env: dict[str, str]) -> None:
        in_process(env)
        import rclpy
        from geometry_msgs.msg import WrenchStamped
        from rclpy.qos import QoSProfile, ReliabilityPolicy
        from sensor_msgs.msg import JointState

        self.rclpy, self.profile = rclpy, profiles.load(name)
        self.context = _context()
        self.node = rclpy.create_node("watcher", context=self.context)
        from rclpy.executors import SingleThreadedExecutor

        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)
        qos = QoSProfile(depth=1000, reliability=ReliabilityPolicy.BEST_EFFORT)
        self.states: list[tuple[float, np.ndarray, np.ndarray]] = []
        self.forces: list = []
        self.node.create_subscription(JointState, self.profile.joint_states.topic, self.on_state, qos)
        self.received: list[float] = []     # when each force arrived (monotonic s)
        self.node.create_subscription(message_type(self.profile.force.type), self.profile.force.topic,
                                      self.on_force, qos)
        self.others = {spec.topic: [] for spec in self.profile.state_topics}   # the driver's other state topics
        for spec in self.profile.state_topics:
            self.node.create_subscription(message_type(spec.type), spec.topic, self.others[spec.topic].append, qos)
        self.wrench = self.node.create_publisher(WrenchStamped, "wrench",
                                                 QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE))

    def on_state(self, message) -> None:
        values = dict(zip(message.name, message.position))
        names = self.profile.joint_states.names
        a_or_relative = np.array([values[n] for n in names[:3]])
        # the drivers' formulas inverted (driver_reference.published): waist sign, relative elbow
        if names[0] == "joint_angle_1":
            a = a_or_relative
        else:
            sign = -1.0 if self.profile.name in ("geomagic_touch_ros2", "sawsensablephantom") else 1.0
            a = np.array([sign * a_or_relative[0], a_or_relative[1], a_or_relative[1] + a_or_relative[2]])
        theta = np.array([-a[0], a[1], a[2]])
        self.states.append((time.monotonic(), theta, np.array([values[n] for n in names[3:]])))

    def on_force(self, message) -> None:
        self.forces.append(message)
        self.received.append(time.monotonic())

    def spin(self, seconds: float) -> None:
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            self.executor.spin_once(timeout_sec=0.01)

    def push(self, frame: str, force: tuple[float, float, float], _field: str = "") -> None:
        from geometry_msgs.msg import WrenchStamped

        message = WrenchStamped()
        message.header.frame_id = frame
        message.wrench.force.x, message.wrench.force.y, message.wrench.force.z = force
        self.wrench.publish(message)

    def close(self) -> None:
        self.executor.shutdown()
        self.node.destroy_node()


def tip(theta: np.ndarray) -> np.ndarray:
    """The gimbal centre in frame s (m), by the report's closed form (eq. 10) with the Touch's lengths."""
    return closed_form.forward_kinematics(theta, REPORT)[:3, 3]


def _kind(name: str) -> tuple[str, str, str]:
    """What the transport of a profile's force depends on: its type, reliability and hold."""
    force = profiles.load(name).force
    return force.type, force.qos.reliability, force.hold


def test_every_kind_of_force_message_is_run_over_loopback():
    """LOOPBACK covers every (type, reliability, hold) of the installed profiles, once each."""
    assert sorted({_kind(name) for name in INSTALLED}) == sorted(_kind(name) for name in LOOPBACK)


@pytest.mark.slow
@pytest.mark.parametrize("name", LOOPBACK)
def test_the_stylus_floats_with_the_node_and_a_users_force_lifts_it(name):
    """The node and the simulated driver started together (the driver holds the stylus until the
    watcher has the states and the node's forces, then SIGUSR1 lets it go); after the release the
    tip stays within 2 mm for FLOAT s, every force received holds the closed form's gravity at the
    release posture by the driver's own formula (1e-9 N m), and 0.5 N up on `wrench` lifts the tip
    (kinisi's one-tick driver: _one_tick); a bad wrench is dropped with one warning naming its
    field. The simulated driver's count of ticks with a command is printed, and the share of the
    states the node answered after the release: asserted above ANSWERED_FLOOR (10 %) only, the
    lowest measured with both cores busy being 27.8 % (50 runs, DEVELOPERS.md): what is
    ours is every force right, not how many a loaded machine lets the node answer."""
    env = _environment()
    node = _start(env, "ros2", "--driver", name)
    simulated = _start(env, "sim-driver", "--driver", name, "--hold", str(HOLD), "--theta0", *map(str, THETA0))
    watcher = Watcher(name, env)
    try:
        _wait_for(node, "joint_states ->")
        _float_and_lift(name, watcher, simulated)
    finally:
        watcher.close()
        results = [_stop(process) for process in (simulated, node)]
    print(next(line for line in results[0][1].splitlines() if "servo ticks after the release" in line))
    _clean_stops(name, results)


def _clean_stops(name: str, results: list[tuple[int, str]]) -> None:
    """Both stopped with 0 and no traceback; the node's log says the bad wrench once, naming its field."""
    for code, err in results:
        assert code == 0 and "Traceback" not in err, err
    warnings = [line for line in results[1][1].splitlines() if "dropped a wrench message" in line]
    assert len(warnings) == 1 and BAD_WRENCH[name][2] in warnings[0], warnings


def _float_and_lift(name: str, watcher: Watcher, simulated: subprocess.Popen, floor: float = ANSWERED_FLOOR) -> None:
    """Held until the watcher has the driver's states and the node's forces (over ONE_TICK_SPAN s
    for kinisi's driver) and the node's subscription to the watcher's wrench matched (a wrench pushed before
    is lost: the node's warning about the bad one below went missing once), then let go
    (SIGUSR1); the float (or kinisi's node part), the lift and a bad wrench."""
    span = ONE_TICK_SPAN if watcher.profile.force.hold == "one_tick" else READY_SPAN

    def ready() -> bool:
        return (min(len(watcher.states), len(watcher.forces)) >= READY
                and watcher.received[-1] - watcher.received[0] >= span
                and watcher.wrench.get_subscription_count() >= 1)

    deadline = time.monotonic() + HOLD
    while not ready() and time.monotonic() < deadline:
        watcher.spin(0.05)
        assert simulated.poll() is None, simulated.communicate()[1]
    assert ready(), (f"within the {HOLD} s hold: {len(watcher.states)} states, {len(watcher.forces)} forces, "
                     f"{watcher.wrench.get_subscription_count()} subscriptions to wrench")
    # and the driver itself has had commands for READY_SPAN s: the watcher's receiving forces says
    # nothing of the driver's subscription (through the relay, a third process, it was matched late in
    # 2 of 10 loaded runs: the stylus fell from the release without a command), and a loaded driver's
    # loop runs its ticks up to CATCH_UP ms behind the commands' arrival (a first command 0.1 s before
    # the release let it sink 0.4 mm first, once in 10 loaded runs)
    _wait_for(simulated, FIRST_COMMAND, timeout=HOLD, watcher=watcher)
    watcher.spin(READY_SPAN)
    simulated.send_signal(signal.SIGUSR1)
    _wait_for(simulated, "released", timeout=10.0, watcher=watcher)   # at once, not after HOLD
    watcher.spin(0.05)
    released = watcher.states[-1][0]
    watcher.spin(FLOAT)
    floating = [tip(theta) for at, theta, _ in watcher.states if at >= released]
    drift = np.linalg.norm(np.array(floating) - tip(THETA0), axis=1).max()
    answered = sum(at >= released for at in watcher.received) / len(floating)   # after the release
    print(f"\n{name}: {len(floating)} states after the release, drift {drift * 1e3:.3f} mm, "
          f"{100 * answered:.1f} % of all states answered (ANSWERED {answered:.4f})")
    assert answered > floor, f"{100 * answered:.1f} % of the states answered"
    if watcher.profile.force.hold == "one_tick":
        _one_tick(watcher)
    else:
        _floats_and_lifts(name, watcher, drift)
    # a bad wrench, one kind per profile (the warnings are throttled to one a second): dropped with a
    # warning naming the field (checked by the caller), nothing sent beyond the driver's clamp or not finite
    watcher.push(*BAD_WRENCH[name])
    watcher.spin(0.2)
    sent = np.array([ref.FORCE[name](force) for force in watcher.forces])
    assert np.isfinite(sent).all() and np.linalg.norm(sent, axis=1).max() <= watcher.profile.force.clamp * (1 + 1e-12)


def _one_tick(watcher: Watcher) -> None:
    """kinisi's driver renders a command in the one servo tick after it arrives (hd++.cpp 138-145):
    the stylus floats only where a command arrives within every 1 ms tick, which ROS 2 on this
    shared 2-core machine does not give (docs/drivers.md: the measured shares; the simulated driver
    logs its own, printed by the caller). The node's part, asserted: every force it sent while the
    stylus stood at the release posture holds the closed form's gravity there by the driver's own
    formula (1e-9 N m); the share of the states it answered is the caller's (ANSWERED_FLOOR)."""
    moved = next((at for at, theta, _ in watcher.states if np.abs(theta - THETA0).max() > 1e-12), np.inf)
    jacobian, gravity = ref.tip_jacobian(THETA0), ref.gravity(THETA0, np.zeros(3), REPORT)
    errors = [np.abs(jacobian.T @ ref.FORCE[watcher.profile.name](force) - gravity).max()
              for force, at in zip(watcher.forces, watcher.received) if at < moved - 0.2]   # answers to still states
    assert len(errors) > 100 and max(errors) < 1e-9, (len(errors), max(errors))


def _floats_and_lifts(name: str, watcher: Watcher, drift: float) -> None:
    """A driver that holds its force: the stylus floats, the forces hold gravity, 0.5 N up lifts it."""
    assert drift < 2e-3
    # the driver's other state topics arrive with the joint states, in its frame_id
    assert all(len(m) > 100 and {x.header.frame_id for x in m} == {spec.frame_id}
               for spec, m in ((s, watcher.others[s.topic]) for s in watcher.profile.state_topics)), \
        {k: len(v) for k, v in watcher.others.items()}
    # (c) every force received so far, by the driver's own formula: the closed form's gravity at the
    # release posture (the stylus still there), the gimbal at the driver's locked_at (0)
    jacobian, gravity = ref.tip_jacobian(THETA0), ref.gravity(THETA0, np.zeros(3), REPORT)
    errors = [np.abs(jacobian.T @ ref.FORCE[name](force) - gravity).max() for force in watcher.forces]
    assert drift < 1e-12 and len(errors) > 100 and max(errors) < 1e-9, (drift, len(errors), max(errors))
    # a user's 0.5 N up (base_link +z = frame s's +y), held (pushed every 20 ms) until the tip rose 1 mm
    # or LIFT_WAIT s passed, then none: the highest the tip got since the first push (it floats within
    # 1e-12 m without one, above). 0.1 s of pushes then none had failed under load: the node took the
    # burst at once and the last, zero, before its next state (2 of 10 runs with both cores busy)
    count, before = len(watcher.states), tip(watcher.states[-1][1])[1]
    deadline, after = time.monotonic() + LIFT_WAIT, before
    while after - before <= 1e-3 and time.monotonic() < deadline:
        watcher.push("base_link", (0.0, 0.0, 0.5))
        watcher.spin(0.02)
        after = max((tip(theta)[1] for _, theta, _ in watcher.states[count:]), default=before)
    watcher.push("base_link", (0.0, 0.0, 0.0))
    # the driver goes on publishing: 10 states more within a second (a 200 Hz driver whose tip rose
    # within 30 ms had published 6 when the lift ended, on an idle machine)
    deadline = time.monotonic() + 1.0
    while len(watcher.states) <= count + 10 and time.monotonic() < deadline:
        watcher.spin(0.02)
    assert len(watcher.states) > count + 10, "the simulated driver stopped publishing"
    print(f"{name}: {len(errors)} forces checked against the closed form; 0.5 N up lifted the tip "
          f"{(after - before) * 1e3:.1f} mm")
    assert after - before > 1e-3


#: The documents that print the one-file relay for the omni_msgs driver (`ros2 --relay`).
ROOT = Path(__file__).resolve().parents[2]
#: The documents that print the relay: README.md and the documentation pages with an OmniFeedback block.
RELAY = re.compile(r"```python(?:-norun)?\n[^`]*OmniFeedback")
DOCUMENTS = [ROOT / "README.md", *(ROOT / "docs").rglob("*.md")]
RELAY_DOCUMENTS = tuple(sorted(str(path.relative_to(ROOT)) for path in DOCUMENTS if RELAY.search(path.read_text())))
#: omni_msgs.msg in place of the driver's workspace: OmniFeedback as geometry_msgs/Wrench.
STAND_IN = "from geometry_msgs.msg import Wrench as OmniFeedback\n"


def relay_block(document: str) -> str:
    """The one python block of ``document`` that uses omni_msgs' OmniFeedback, as printed."""
    text = (Path(__file__).resolve().parents[2] / document).read_text()
    blocks = [b for b in re.findall(r"```python(?:-norun)?\n(.*?)```", text, re.DOTALL) if "OmniFeedback" in b]
    assert len(blocks) == 1, f"{document}: {len(blocks)} relay blocks"
    return blocks[0]


def test_the_documents_print_one_relay():
    """Some document prints the relay, and every one that does prints the same block (the one run
    below)."""
    assert RELAY_DOCUMENTS and len({relay_block(document) for document in RELAY_DOCUMENTS}) == 1


@pytest.mark.slow
@pytest.mark.parametrize("document", RELAY_DOCUMENTS[-1:])
def test_the_documented_relay_carries_the_nodes_force_to_the_geomagic_driver(document, tmp_path, monkeypatch):
    """The relay block of ``document``, executed exactly as printed (a script of its own, as a user
    runs it), between the node (`ros2 --driver geomagic_touch_ros2 --relay`: Vector3 on
    /phantom/force_feedback_relay) and the simulated geomagic driver (OmniFeedback on
    /phantom/force_feedback): the stylus floats (within 2 mm for FLOAT s, every force the driver receives
    holding the closed form's gravity by the driver's own formula, 1e-9 N m), 0.5 N up lifts it, and
    the forces the driver receives are, bit for bit, ones the node sent to the relay (at least
    SEEN_FLOOR, 50 %, of them seen by the watcher, 88.9 % at the lowest with both cores busy; the
    share of states answered printed and above RELAYED_FLOOR, 3 %, 8.6 % at the lowest).

    omni_msgs is not on PyPI and cannot be installed here (it is built in the driver's ROS
    workspace), so the relay, the simulated driver and this test's watcher import a stand-in
    package whose omni_msgs.msg.OmniFeedback is geometry_msgs/msg/Wrench: a real ROS message
    whose ``force`` is a geometry_msgs/Vector3 as OmniFeedback's is (its other field is ``torque``
    where OmniFeedback has ``position``, which neither the relay nor the driver's force path sets,
    omni_state.cpp 183-196). What this cannot check is the real type's name and wire format."""
    from geometry_msgs.msg import Vector3
    from rclpy.qos import QoSProfile, ReliabilityPolicy

    name = "geomagic_touch_ros2"
    package = tmp_path / "omni_msgs"
    (package / "msg").mkdir(parents=True)
    (package / "__init__.py").write_text("")
    (package / "msg" / "__init__.py").write_text(STAND_IN)
    (tmp_path / "phantom_pin_relay.py").write_text(relay_block(document))
    stand_in = types.ModuleType("omni_msgs.msg")
    exec(STAND_IN, stand_in.__dict__)
    monkeypatch.setitem(sys.modules, "omni_msgs", types.ModuleType("omni_msgs"))
    monkeypatch.setitem(sys.modules, "omni_msgs.msg", stand_in)
    env = _environment()
    workspace = {**env, "PYTHONPATH": os.pathsep.join(filter(None, (str(tmp_path), env.get("PYTHONPATH"))))}
    node = _start(env, "ros2", "--driver", name, "--relay")      # without the stand-in: Vector3 only
    relay = subprocess.Popen([sys.executable, str(tmp_path / "phantom_pin_relay.py")], env=workspace,
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    simulated = _start(workspace, "sim-driver", "--driver", name, "--hold", str(HOLD), "--theta0", *map(str, THETA0))
    watcher = Watcher(name, env)
    relayed: list = []
    watcher.node.create_subscription(Vector3, "/phantom/force_feedback" + profiles.RELAY, relayed.append,
                                     QoSProfile(depth=1000, reliability=ReliabilityPolicy.BEST_EFFORT))
    try:
        _wait_for(node, "joint_states ->")
        _float_and_lift(name, watcher, simulated, RELAYED_FLOOR)
        assert relay.poll() is None, relay.communicate()[1]
    finally:
        watcher.close()
        results = [_stop(process) for process in (simulated, node)]
        relay.kill()
        relay.communicate()
    _clean_stops(name, results)
    sent = {(v.x, v.y, v.z) for v in relayed}
    received = [(f.force.x, f.force.y, f.force.z) for f in watcher.forces]
    seen = sum(f in sent for f in received) / max(len(received), 1)
    print(f"relay: {len(received)} forces received by the driver, {len(sent)} distinct seen sent to the relay, "
          f"{100 * seen:.1f} % of the received among them (SEEN {seen:.4f})")
    assert len(received) > 100 and seen > SEEN_FLOOR, (len(received), len(sent), seen)


@pytest.mark.slow
def test_without_the_node_the_stylus_falls():
    """The simulated driver alone (sawsensablephantom): more than 10 mm down within 3 s of the release."""
    env = _environment()
    watcher = Watcher("sawsensablephantom", env)
    simulated = _start(env, "sim-driver", "--driver", "sawsensablephantom", "--hold", "0.5",
                       "--theta0", *map(str, THETA0))
    try:
        _wait_for(simulated, "released", watcher=watcher)
        deadline, fallen = time.monotonic() + 3.0, 0.0
        while fallen <= 10e-3 and time.monotonic() < deadline:   # read until it fell 10 mm or 3 s passed
            watcher.spin(0.05)
            fallen = tip(THETA0)[1] - min((tip(theta)[1] for _, theta, _ in watcher.states), default=tip(THETA0)[1])
        assert fallen > 10e-3
    finally:
        watcher.close()
        code, err = _stop(simulated)
    assert code == 0, err
