"""The simulated driver without ROS (phantom_pin.interfaces.ros2.simulated_driver.DriverSimulation): the force it
renders against each driver's own formula (its damping, spring, clamp and hold transcribed from
its source lines), and, in lockstep with the node's computation (ros2.DriverBridge), the stylus
floating where it was released, falling without the compensation, and moved by a user's force:
the displacements measured on the tip of the report's closed-form kinematics."""

from __future__ import annotations

import numpy as np
import pytest

from helpers import message
from phantom_pin import Device, Phantom, closed_form
from phantom_pin.interfaces import profiles
from phantom_pin.interfaces.ros2.node import DriverBridge, fill_force
from phantom_pin.interfaces.ros2.simulated_driver import DriverSimulation
from references import driver as ref

PROFILES = profiles.names()
#: Seeded releases where gravity beats static friction (|G| > 0.01 N m on joints 2 and 3).
RELEASES = [np.array([0.2, 0.6, 0.5]), np.array([-0.3, 0.9, 0.2])]


@pytest.fixture(scope="module")
def device() -> Device:
    return Device(Phantom.from_model("touch"))


def tip(device: Device, theta) -> np.ndarray:
    """The gimbal centre in frame s (m), by the report's closed form (eq. 10)."""
    return closed_form.forward_kinematics(np.asarray(theta), device.config.report)[:3, 3]


def test_the_simulated_drivers_render_as_their_sources_say(device):
    """One tick's HD_CURRENT_FORCE for a command m, the stylus moving at v: geomagic's A m - 1 N s/m v
    (0.001 N/(mm/s), omni_state.cpp 189-191, 320-325); CalaW's B^T(m) + 45 N/m (x0 - x) - 2.5 N s/m v
    (touch_driver_node.cpp 176-199, 271-291), its 8 N clamp; saw's 2 N clamp; kinisi's command for one
    tick only (hd++.cpp 138-145, phantom_touch_control_node.cpp 197-211)."""
    theta0 = np.array([0.1, 0.5, 0.6])
    command = np.array([0.3, -0.2, 0.1])
    for name in PROFILES:
        profile = profiles.load(name)
        simulation = DriverSimulation(device, profile, theta0)
        simulation.q, simulation.v = [0.12, 0.48, 0.61], [0.5, -0.4, 0.3]
        jacobian = ref.tip_jacobian(np.array(simulation.q))
        velocity = jacobian @ np.array(simulation.v)
        sent = message(profile)
        fill_force(sent, profile, command)
        simulation.command(command)
        want = ref.FORCE[name](sent)
        if name == "geomagic_touch_ros2":
            want = want - 1.0 * velocity
        if name == "touch_ros2_control":
            x0, x = tip(device, theta0), tip(device, simulation.q)
            want = ref.FORCE[name](SimpleWrench(np.array([want[2], want[0], want[1]])
                                                + [45 * (x0 - x)[2], 45 * (x0 - x)[0], 45 * (x0 - x)[1]]
                                                - 2.5 * np.array([velocity[2], velocity[0], velocity[1]])))
        assert np.abs(simulation.force(jacobian) - want).max() < 1e-12, name
        simulation.tick()
        second = simulation.force(ref.tip_jacobian(np.array(simulation.q)))
        if name == "phantom_touch_ros2":
            assert np.abs(second).max() == 0.0   # one tick after its message only
    big = DriverSimulation(device, profiles.load("sawsensablephantom"), theta0)
    big.command([30.0, 0.0, 0.0])
    assert np.linalg.norm(big.force(ref.tip_jacobian(theta0))) == pytest.approx(2.0, rel=1e-12)


def test_a_command_counts_for_the_servo_tick_after_it_arrived(device):
    """Commands given with their arrival times and ticks with theirs (s, one clock; seeded): each
    tick renders J^T F of the latest command arrived by its time (saw holds it), kinisi's only of one
    arrived since the previous tick (hd++.cpp 138-145: the callback stores the force and sets a flag,
    the next servo tick sends it and clears the flag; nothing otherwise), whatever the order the
    loop hands them over in. The stylus held (before ``hold``), so J is the release posture's."""
    rng = np.random.default_rng(5)
    arrivals = rng.uniform(0.0, 0.02, 30)
    commands = rng.uniform(-1.0, 1.0, (30, 3))           # N, under saw's 2 N clamp
    jacobian = ref.tip_jacobian(RELEASES[0])
    for name in ("phantom_touch_ros2", "sawsensablephantom"):
        simulation = DriverSimulation(device, profiles.load(name), RELEASES[0], hold=1.0)
        for t, c in zip(arrivals, commands):
            simulation.command(c, at=t)
        one_tick = name == "phantom_touch_ros2"
        for k in range(1, 22):
            simulation.tick(at=k * 1e-3)
            since = (k - 1) * 1e-3 if one_tick else -np.inf   # kinisi: arrived since the previous tick only
            arrived = [i for i in range(30) if since < arrivals[i] <= k * 1e-3]
            want = jacobian.T @ commands[max(arrived, key=lambda i: arrivals[i])] if arrived else np.zeros(3)
            assert np.abs(simulation.applied - want).max() < 1e-12, (name, k)


def test_release_lets_the_stylus_go_at_the_next_tick_and_not_before(device):
    """hold=10 s, no command: the stylus stays at theta0 (to the bit) for 50 ticks; release()
    lets it go at the end of the next tick, the same state as a hold of 51 ticks given at the start
    (to the bit), and gravity then pulls the tip down (frame s's -y: more than 0.1 mm in 0.1 s, where
    gravity beats the static friction); a second release() changes nothing."""
    simulation = DriverSimulation(device, profiles.load("sawsensablephantom"), RELEASES[0], hold=10.0)
    for _ in range(50):
        simulation.tick()
    assert simulation.q == list(RELEASES[0]) and simulation.ticks == 0
    simulation.release()
    simulation.tick()
    assert simulation.ticks == 0 and simulation.q == list(RELEASES[0])   # let go at the end of this tick
    given = DriverSimulation(device, profiles.load("sawsensablephantom"), RELEASES[0], hold=0.051)
    for _ in range(51):
        given.tick()
    for _ in range(100):
        simulation.tick()
        given.tick()
    hold = simulation.hold
    simulation.release()                                                  # let go already: nothing
    assert simulation.hold == hold and simulation.ticks == given.ticks == 100 and simulation.q == given.q
    assert tip(device, RELEASES[0])[1] - tip(device, simulation.q)[1] > 1e-4


class SimpleWrench:
    """A WrenchStamped-shaped holder of a force in CalaW's driver frame R."""

    def __init__(self, force: np.ndarray) -> None:
        from types import SimpleNamespace

        self.wrench = SimpleNamespace(force=SimpleNamespace(x=force[0], y=force[1], z=force[2]))


def run(device: Device, name: str, theta0: np.ndarray, seconds: float, compensate=("gravity",),
        user: tuple[str, np.ndarray] | None = None) -> np.ndarray:
    """The driver simulated for ``seconds`` with the node's computation answering each of its
    joint_states (at the driver's rate; the answer applied from the next tick): the tip (m, frame
    s) at each tick."""
    profile = profiles.load(name)
    simulation = DriverSimulation(device, profile, theta0)
    bridge = DriverBridge(device.phantom, profile, compensate)
    every = round(1000 / profile.joint_states.rate)
    gimbal = np.zeros(3)
    tips = []
    for k in range(round(seconds * 1000)):
        if k % every == 0:
            names, positions, _ = simulation.joint_state(gimbal)
            theta, g = bridge.state(names, positions)
            force = np.zeros(3) if user is None else bridge.user_force(user[0], user[1], theta, g)
            simulation.command(bridge.renderer(theta, g, force, time=k * 1e-3).message)
        simulation.tick()
        tips.append(tip(device, simulation.q))
    return np.array(tips)


@pytest.mark.parametrize("name", PROFILES)
def test_the_stylus_floats_where_it_is_released_and_falls_without_compensation(device, name):
    """Released at rest: within 2 mm of the release for 5 s with the node's compensation; more
    than 10 mm down (frame s's -y) within 3 s without (gravity beats the static friction there),
    but for CalaW's driver, whose own 45 N/m spring to its start-up position (touch_driver_node.cpp
    176-199) holds the stylus 5-10 mm below it: more than 5 mm there."""
    report = device.config.report
    for theta0 in RELEASES[PROFILES.index(name) % 2:][:1]:   # the releases taken in turn by the profiles
        g = ref.gravity(theta0, np.zeros(3), report)
        assert np.all(np.abs(g[1:]) > 0.01)     # beyond the Coulomb torque, 0.01 N m
        start = tip(device, theta0)
        held = run(device, name, theta0, 5.0)
        assert np.linalg.norm(held - start, axis=1).max() < 2e-3
        fallen = run(device, name, theta0, 3.0, compensate=())
        assert (start[1] - fallen[:, 1]).max() > (5e-3 if name == "touch_ros2_control" else 10e-3)


@pytest.mark.parametrize("name", PROFILES)
def test_a_users_force_moves_the_stylus_its_way(device, name):
    """0.5 N up (base_link +z, frame s's +y) lifts the tip; 0.5 N along the stylus axis (its frame's
    +z, Ubitrack's rotation) moves it along that axis: more than 1 mm in 0.1 s each (before a
    stop: the tip's acceleration J M^-1 J^T F has a positive component along F)."""
    theta0 = RELEASES[0]
    start = tip(device, theta0)
    lifted = run(device, name, theta0, 0.1, user=("base_link", np.array([0.0, 0.0, 0.5])))
    assert lifted[-1, 1] - start[1] > 1e-3
    axis = ref.stylus_rotation(theta0, np.zeros(3))[:, 2]
    pushed = run(device, name, theta0, 0.1, user=("stylus", np.array([0.0, 0.0, 0.5])))
    assert (pushed[-1] - start) @ axis > 1e-3


def test_the_state_topics_are_each_drivers_own_of_the_stylus_pose_and_velocity(device):
    """HD_CURRENT_TRANSFORM of the stylus (Ubitrack's position and rotation of OpenHaptics' angles,
    plus frame s's origin in OpenHaptics' coordinates from gimbal.yaml's openhaptics_shoulder, an
    ESTIMATE) and its velocities (complex steps of Ubitrack's formulas along the joint rates), each
    through the driver's own formula (driver_reference.STATE; geomagic's through OpenHaptics'
    hduMatrix and hduQuaternion, both branches of its quaternion taken): 1e-12, at a fixed and
    seeded states inside the stops and the gimbal's ranges."""
    import yaml

    from references.gimbal import derivative, openhaptics, ubitrack

    shoulder = np.array(yaml.safe_load((ref.TOUCH / "gimbal.yaml").read_text())["openhaptics_shoulder"])
    origin = shoulder - [0.0, ref.L2, -ref.L1]       # the zero posture's gimbal centre in OpenHaptics' frame
    thetas, gimbals = ref.states(6, seed=41)
    rng = np.random.default_rng(41)
    seen, traces = set(), []
    for theta, gimbal in [(np.array([0.15, 0.55, 0.62]), np.zeros(3)), *zip(thetas, gimbals)]:
        rates = rng.uniform(-0.5, 0.5, 3)
        position, rotation = ubitrack(openhaptics(theta, gimbal))

        def along(function, theta=theta, rates=rates):   # d function(theta + s rates)/ds at s = 0, complex step
            return derivative(lambda s: function(theta + s[0] * rates), np.zeros(1), 0)

        velocity = along(lambda t, g=gimbal: ubitrack(openhaptics(t, g))[0])
        spin = along(lambda t, g=gimbal: ubitrack(openhaptics(t, g))[1]) @ rotation.T
        angular = np.array([spin[2, 1], spin[0, 2], spin[1, 0]])
        traces.append(np.trace(np.array([[0.0, -1, 0], [1, 0, 0], [0, 0, 1]]) @ rotation.T))   # geomagic's branch
        for name in PROFILES:
            simulation = DriverSimulation(device, profiles.load(name), theta)
            simulation.q, simulation.v = list(theta), list(rates)
            for spec, first, second in simulation.state_topics(gimbal):
                kind, formula = ref.STATE[spec.topic]
                want = formula(position + origin, rotation) if kind == "pose" else formula(velocity, angular)
                assert np.abs(first - want[0]).max() < 1e-12 and np.abs(second - want[1]).max() < 1e-12, spec.topic
                seen.add(spec.topic)
    assert seen == set(ref.STATE)
    assert min(traces) <= 0 < max(traces), traces


@pytest.mark.parametrize("name", [n for n in PROFILES if profiles.load(n).joint_states.effort_unit == "mN m"])
def test_the_published_efforts_are_openhaptics_joint_torques_in_mN_m(device, name):
    """Mutant 18. The drivers that publish HD_CURRENT_JOINT_TORQUE or HD_LAST_JOINT_TORQUE
    (sawSensablePhantom, CalaW's, RViMLab's) publish OpenHaptics' unit, mN m, on its own angles
    a = (-theta1, theta2, theta3): by the power, T . da = tau . dtheta, T = 1000 (-tau1, tau2,
    tau3) for the joint torques tau = J^T F (N m) of the force the tick rendered (the driver's own
    formula of the command, the reference's J by complex steps; at rest at its start-up posture:
    no spring, no damping), the gimbal's 0; 1e-9 mN m."""
    theta0 = np.array([0.1, 0.5, 0.6])
    profile = profiles.load(name)
    simulation = DriverSimulation(device, profile, theta0)
    command = np.array([0.3, -0.2, 0.1])
    sent = message(profile)
    fill_force(sent, profile, command)
    simulation.command(command)
    simulation.tick()
    tau = ref.tip_jacobian(theta0).T @ ref.FORCE[name](sent)
    _, _, efforts = simulation.joint_state(np.zeros(3))
    np.testing.assert_allclose(efforts, [*(1000.0 * np.array([-tau[0], tau[1], tau[2]])), 0, 0, 0], rtol=0, atol=1e-9)
    assert np.abs(efforts[:3]).max() > 10.0   # tens of mN m: a unit off by 1000 cannot hide
