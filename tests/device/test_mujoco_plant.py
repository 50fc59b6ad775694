"""The same device in two plants: phantom_pin.simulate and MuJoCo on the generated MJCF
(phantom_pin.device.mujoco_plant), driven by the same controllers at 1 kHz with a zero-order
hold. Friction with stiction, the stops, and the saturation policy mean the same in both; the
bounds below are the measured agreement (in the comments), with some margin."""

import numpy as np
import pytest

from phantom_pin import Device, InvalidInputError, Phantom, describe, simulate
from phantom_pin.device.mujoco_plant import simulate_mujoco

DEVICE = Device(Phantom(describe()))
GRAVITY = DEVICE.phantom.gravity
START = np.array([0.0, 0.3, 0.4])                  # rad
COULOMB = np.array(DEVICE.config.actuation.friction.coulomb)   # N m, each joint's breakaway torque


def both(theta0, duration, controller):
    return (simulate(theta0, duration, controller, device=DEVICE),
            simulate_mujoco(theta0, duration, controller, device=DEVICE))


@pytest.mark.parametrize("share", [0.5, 0.99])
def test_below_the_breakaway_torque_the_arm_holds_in_both(share):
    """A constant torque on joint 1 (vertical axis: no gravity) below the Coulomb torque, the arm
    gravity-compensated: simulate sticks exactly (0 rad), MuJoCo's soft frictionloss (solref 2
    timesteps) creeps 1.5e-4 rad at half the torque (its default 0.02 s: 1.5e-3); both well under
    1e-3 rad in 1 s."""
    ours, mujoco = both(START, 1.0, lambda t, q, v: GRAVITY(q) + [share * COULOMB[0], 0.0, 0.0])
    assert np.abs(ours.theta - START).max() == 0.0
    assert np.abs(mujoco.theta[-1] - START).max() < (2e-4 if share == 0.5 else 1e-3)


def test_above_the_breakaway_torque_both_move_alike():
    """Twice the Coulomb torque: joint 1 runs into its stop in both (1.249 rad in 1 s, within
    2.0e-4 rad of each other)."""
    ours, mujoco = both(START, 1.0, lambda t, q, v: GRAVITY(q) + [2 * COULOMB[0], 0.0, 0.0])
    assert ours.theta[-1, 0] - START[0] > 1.0
    assert np.abs(ours.theta[-1] - mujoco.theta[-1]).max() < 5e-4              # measured 2.0e-4


def test_a_pd_hold_with_gravity_compensation_sticks_inside_the_friction_band():
    """PD towards START + 10 mrad with 0.5 N m/rad: 5 mN m, half the Coulomb torque: a real arm
    sticks anywhere within Coulomb / Kp = 20 mrad of the target. simulate does not move at all;
    MuJoCo creeps 1.3 mrad towards it in 2 s."""
    target = START + 0.01
    ours, mujoco = both(START, 2.0, lambda t, q, v: GRAVITY(q) + 0.5 * (target - q) - 0.01 * v)
    assert (ours.theta == START).all()
    assert (np.abs(mujoco.theta[-1] - target) <= COULOMB / 0.5).all()
    assert np.abs(ours.theta - mujoco.theta).max() < 2e-3                      # measured 1.3e-3 rad


@pytest.mark.parametrize("stops", [{}, {"stops.stiffness": 100.0, "stops.damping": 1.0}])
@pytest.mark.parametrize("theta0", [[0.0, 0.3, 0.4], [0.3, 0.8, 0.4]])
def test_a_free_fall_onto_the_stops_agrees(theta0, stops):
    """Unpowered from rest: the arm falls onto the parallelogram's stop and bounces along it.
    MuJoCo's limits (the configuration's K and B per mjcf.yaml's stop_inertia, with its
    stop_solimp: a fit to simulate's spring-damper) follow simulate within 0.048 rad over 1.5 s
    with the shipped stops (MuJoCo's default limits: 0.33), and within 0.054 rad with stops ten
    times stiffer and damper (before the MJCF took K and B, its limits stayed those fitted to the
    shipped stops: 0.33 rad)."""
    device = Device(Phantom(describe(overrides=stops))) if stops else DEVICE
    ours = simulate(np.array(theta0), 1.5, None, device=device)
    mujoco = simulate_mujoco(np.array(theta0), 1.5, None, device=device)
    assert np.abs(ours.theta - mujoco.theta).max() < 0.065
    bound = device.config.limits.stops.coupled.theta3_minus_theta2_max
    for result in (ours, mujoco):                                             # both hit the stop
        assert (result.theta[:, 2] - result.theta[:, 1]).max() > bound


def test_a_1000_newton_per_metre_wall_settles_in_both_at_the_same_depth():
    """examples/virtual_wall.py's wall (the floor through the tip of START, F = K depth along +y in
    frame s, a 1 N push down, gravity compensated) at 1000 N/m: both settle (less than 0.1 mm
    peak to peak over the last 0.1 s; simulate sticks, 0) and agree on the depth within 0.1 mm
    (Hooke: 1 mm; the stiction band leaves simulate at 0.982 mm)."""
    phantom, stiffness, push = DEVICE.phantom, 1000.0, 1.0
    normal = np.array([0.0, 1.0, 0.0])
    surface = phantom.forward_kinematics(START)[:3, 3]
    start = phantom.inverse_kinematics(surface - (push / stiffness + 1e-3) * normal)

    def controller(t, theta, dtheta):
        pose = phantom.forward_kinematics(theta)
        depth = (surface - pose[:3, 3]) @ normal
        force = (stiffness * depth if depth > 0 else 0.0) - push
        return GRAVITY(theta) + (pose[:3, :3] @ phantom.body_jacobian(theta)[:3]).T @ (force * normal)

    depths = []
    for result in both(start, 0.5, controller):
        depth = (surface - result.tip) @ normal
        last = depth[result.t > 0.4]
        assert np.ptp(last) < 1e-4, np.ptp(last)
        depths.append(last.mean())
    assert abs(depths[0] - depths[1]) < 1e-4, depths
    assert abs(depths[0] - push / stiffness) < 0.05 * push / stiffness


def test_both_saturate_at_the_same_torque():
    """actuation.yaml's saturation policy (continuous) in simulate and in the MJCF's ctrlrange: a
    5 N m command becomes the motors' continuous torque x ratio in both."""
    ours, mujoco = both(START, 0.01, lambda t, q, v: [5.0, -5.0, 5.0])
    np.testing.assert_allclose(ours.tau, mujoco.tau, rtol=1e-12)
    np.testing.assert_allclose(ours.tau[0], DEVICE.continuous_torque * [1, -1, 1], rtol=1e-12)


@pytest.mark.parametrize("plant", [simulate, simulate_mujoco])
def test_both_refuse_a_diverging_state_and_a_start_a_turn_beyond_the_stops(plant, tmp_path, monkeypatch):
    """1e4 rad/s at the start diverges in both: an InvalidInputError naming the cause, no result.
    MuJoCo by itself warns, writes MUJOCO_LOG.TXT into the working directory, resets the model
    to its initial state and goes on (before: theta 0.1, -1551, 0 rad, returned as a result);
    simulate_mujoco writes no log. A start 28 rad beyond the stops is refused by both."""
    monkeypatch.chdir(tmp_path)
    with pytest.raises(InvalidInputError, match="^dtheta0: 1e\\+04 rad/s|^controller or dtheta0: .* diverged"):
        plant([0.1, 0.3, 0.4], 0.01, None, dtheta0=[1e4, 0.0, 0.0], device=DEVICE)
    assert list(tmp_path.iterdir()) == []
    with pytest.raises(InvalidInputError, match="^theta0: .* beyond the stops, more than a turn"):
        plant([30.0, 0.3, 0.4], 0.01, None, device=DEVICE)


@pytest.mark.parametrize("kwargs, message", [
    ({"timestep": 5e-324}, "^timestep: inf MuJoCo steps"),                      # was OverflowError
    ({"timestep": 1e-12}, "^timestep: 1e\\+09 MuJoCo steps of 1e-12 s per sample"),  # ran for hours
    ({"timestep": 3e-4}, "^timestep: 1000 Hz is not 1 / timestep \\(3333.33 Hz\\) divided by a whole number$"),
    ({"rate": 300.0}, "^rate: 300 Hz is not 1 / timestep \\(1000 Hz\\) .*; pass timestep$"),
])
def test_simulate_mujoco_refuses_bad_steps_naming_them(kwargs, message):
    """Found by a bad-input pass: a tiny timestep overflowed or ran without bound, a timestep
    not dividing the period was blamed on the rate."""
    with pytest.raises(InvalidInputError, match=message):
        simulate_mujoco(START, 0.01, None, device=DEVICE, **kwargs)
