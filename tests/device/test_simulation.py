"""simulate(): against an RK4 integration of the closed form written here (another step),
energy (kinetic + potential + stop springs, from the closed form and the published stop
stiffness), the static equilibrium at the stops, and the zero-order hold, saturation and
quantization of the controller's samples."""

import math

import numpy as np
import pytest

from helpers import HELD, REPORT
from phantom_pin import Device, InvalidInputError, MissingDataError, Phantom, closed_form, simulate
from phantom_pin.device.simulation import default_device

START = np.array([0.3, 0.8, 0.4])                  # rad, released at rest
K_STOP = 10.0                                      # N m/rad, mahilab's hard stop
COULOMB = 0.01                                     # N m, the breakaway (= sliding) friction
#: mahilab's stops as rows of (coordinate gradient, lower, upper) in rad: q1, q2, q3, q2 - q3
GRADIENTS = np.array([[1.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0], [0, 1.0, -1.0]])
LOWER, UPPER = np.radians([-90, -124, -29, -55]), np.radians([90, 119, 214, 65])
PEAK = 0.129 * np.array([13.3, 11.6, 11.6])         # N m: stall torque x ratio
FALL = 15.0                                        # s


def closed_form_rk4(theta0, dtheta0, torque, duration, h):
    """RK4 with step h of M(q) q'' + C(q, q') q' + N(q) = torque(t), the report's closed form."""
    def rate(x, t):
        q, v = x[:3], x[3:]
        a = np.linalg.solve(closed_form.mass_matrix(q, REPORT),
                            torque(t) - closed_form.coriolis_matrix(q, v, REPORT) @ v - closed_form.gravity(q, REPORT))
        return np.concatenate([v, a])

    x, out = np.concatenate([theta0, dtheta0]), []
    for k in range(int(round(duration / h)) + 1):
        out.append(x)
        t = k * h
        k1 = rate(x, t)
        k2 = rate(x + h / 2 * k1, t)
        k3 = rate(x + h / 2 * k2, t)
        k4 = rate(x + h * k3, t)
        x = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    return np.array(out)


def test_without_friction_stops_and_saturation_it_is_the_closed_form():
    result = simulate(START, 0.15, friction=False, hard_stops=False, saturation=False)
    reference = closed_form_rk4(START, np.zeros(3), lambda t: np.zeros(3), 0.15, 1e-4)[::10]
    assert result.t.shape == (151,) and result.t[0] == 0 and result.t[-1] == pytest.approx(0.15, abs=1e-15)
    assert np.abs(result.theta - reference[:, :3]).max() < 1e-9          # measured 3.3e-11 rad
    assert np.abs(result.dtheta - reference[:, 3:]).max() < 1e-8         # rad/s, measured 3.8e-10
    assert np.abs(result.theta[-1] - START).max() > 0.05                 # it did move
    np.testing.assert_allclose(result.tip, closed_form.forward_kinematics(result.theta, REPORT)[:, :3, 3], atol=1e-12)
    slow = simulate(START, 0.15, rate=20.0, friction=False, hard_stops=False, saturation=False)
    assert slow.substeps == 50 and np.abs(slow.theta - reference[::50, :3]).max() < 1e-9  # steps <= 1 ms


def test_the_controller_torque_is_held_between_samples():
    """A torque sampled at 500 Hz and held: the closed form integrated at 1/10 of the
    period with the same held torque."""
    def command(t, theta, dtheta):
        return 0.05 * np.sin(2 * np.pi * 7 * t + np.array([0.0, 1.0, 2.0]))

    result = simulate(START, 0.1, command, rate=500.0, friction=False, hard_stops=False, saturation=False)

    def held(t):
        return command(math.floor(t * 500 * (1 + 1e-12)) / 500, None, None)

    reference = closed_form_rk4(START, np.zeros(3), held, 0.1, 2e-4)[::10]
    assert np.abs(result.theta - reference[:, :3]).max() < 1e-9          # measured 1.5e-11 rad
    np.testing.assert_allclose(result.tau, [command(t, None, None) for t in result.t], rtol=1e-15)


def test_halving_the_substep_changes_little_through_a_stop():
    """0.5 s of free fall, through the first contact with the coupled stop (at 0.3 s)."""
    default = simulate(START, 0.5)
    finer = simulate(START, 0.5, substeps=2 * default.substeps)
    assert default.substeps == 1                                        # the shipped stops need no more
    assert np.abs(default.theta - finer.theta).max() < 1e-6             # measured 1.0e-7 rad


@pytest.mark.parametrize("friction", [False, True])
def test_a_fast_impact_on_a_stop_converges_at_fourth_order(friction):
    """Released at (0, 0.3, 0.4) rad the arm hits the coupled stop at 10 rad/s (at 0.216 s),
    where the stop's damper jumps in with about 1 N m. Against 64 substeps over 0.3 s: the
    default step within 1e-6 rad (measured 8.6e-8 without friction, 6.8e-8 with), halving
    it gains more than 8x (measured 18x, fourth order). Before the stops' contact was held
    over each step up to the event that ends it, a stage past the boundary brought the jump
    into the step that located the contact: 6e-4 rad, the same 8e-7 rad from 4 to 32
    substeps."""
    theta0 = np.array([0.0, 0.3, 0.4])
    reference = simulate(theta0, 0.3, friction=friction, substeps=64).theta
    error = [np.abs(simulate(theta0, 0.3, friction=friction, substeps=n).theta - reference).max() for n in (1, 2)]
    assert error[0] < 1e-6 and error[0] > 8 * error[1]


@pytest.fixture(scope="module")
def fall():
    """FALL seconds from rest at START, unpowered, with friction and stops. Two substeps
    (the default is one; the halving test above covers it) keep the test short."""
    return simulate(START, FALL, substeps=2)


def stop_depth(theta):
    coordinate = theta @ GRADIENTS.T
    return coordinate - np.clip(coordinate, LOWER, UPPER)


def test_mechanical_energy_never_grows_without_input(fall):
    theta, dtheta = fall.theta, fall.dtheta
    energy = (0.5 * np.einsum("ni,nij,nj->n", dtheta, closed_form.mass_matrix(theta, REPORT), dtheta)
              + closed_form.potential_energy(theta, REPORT) + 0.5 * K_STOP * np.sum(stop_depth(theta) ** 2, axis=1))
    assert np.diff(energy).max() < 1e-10                                # J; measured < 0 at every sample
    assert energy[-1] < energy[0] - 0.1                                 # J: it fell and lost it
    assert (np.abs(stop_depth(theta)).max(axis=1) > 0).any()            # and it hit the stops


def test_a_free_fall_comes_to_rest_against_the_parallelogram_stop(fall):
    """The counterweights pull theta3 up until q3 - q2 = 55 deg; the arm bounces on that stop
    and sticks (Coulomb friction with stiction: it stops dead, v = 0 exactly) where the
    torque that holds each joint, gravity less the stop spring, is within the Coulomb torque;
    short of the equilibrium where the spring alone balances gravity (N2 = K p = -N3)."""
    theta, dtheta = fall.theta[-1], fall.dtheta[-1]
    assert dtheta.tolist() == [0.0, 0.0, 0.0]                           # stuck, not creeping
    moving = np.flatnonzero((fall.dtheta != 0).any(axis=1))
    assert moving[-1] < len(fall.t) - 1000 and (fall.theta[moving[-1] + 1:] == theta).all()   # stuck for > 1 s
    depth = stop_depth(theta)
    assert depth[:3].tolist() == [0, 0, 0] and -2e-3 < depth[3] < 0     # only q3 - q2 <= 55 deg
    # at rest 0 = -N + stop + f: the friction that holds is f = N + K p (0, 1, -1), p = depth[3]
    holding = closed_form.gravity(theta, REPORT) + K_STOP * depth[3] * np.array([0.0, 1.0, -1.0])
    assert np.abs(holding).max() <= COULOMB * (1 + 1e-9)
    assert theta[0] == pytest.approx(START[0], abs=1e-12)               # no gravity on theta1


def test_saturation_clips_at_the_configurations_policy():
    """By default (actuation.yaml: saturation continuous) at the motors' continuous torque, as the
    MJCF's ctrlrange: 28.6 mN m x ratio, 0.665 A; with saturation="peak" at the stall torque,
    129 mN m x ratio, 5.5 A."""
    continuous = np.array([0.0286 * 13.3, 0.0286 * 11.6, 0.0286 * 11.6])
    result = simulate(START, 0.01, lambda t, q, dq: [5.0, -5.0, 0.2])
    np.testing.assert_allclose(result.tau_commanded, np.tile([5.0, -5.0, 0.2], (11, 1)))
    np.testing.assert_allclose(result.tau, np.tile([continuous[0], -continuous[1], 0.2], (11, 1)), rtol=1e-15)
    np.testing.assert_allclose(result.current[0], [0.0286 / 0.0234, -0.0286 / 0.0234, 0.2 / (11.6 * 0.0234)])
    result = simulate(START, 0.01, lambda t, q, dq: [5.0, -5.0, 0.5], saturation="peak")
    np.testing.assert_allclose(result.tau, np.tile([PEAK[0], -PEAK[1], 0.5], (11, 1)), rtol=1e-15)
    np.testing.assert_allclose(result.current[0], [0.129 / 0.0234, -0.129 / 0.0234, 0.5 / (11.6 * 0.0234)])
    unclipped = simulate(START, 0.01, lambda t, q, dq: [5.0, -5.0, 0.5], saturation=False)
    np.testing.assert_allclose(unclipped.tau, unclipped.tau_commanded)
    numpy_true = simulate(START, 0.01, lambda t, q, dq: [5.0, -5.0, 0.2], saturation=np.True_)
    np.testing.assert_allclose(numpy_true.tau[0], [continuous[0], -continuous[1], 0.2], rtol=1e-15)  # was the peak


def test_gravity_compensation_holds_the_arm_still():
    """The sign convention: the controller's torque is eq. 80's tau."""
    result = simulate(START, 0.2, lambda t, q, dq: closed_form.gravity(q, REPORT))
    assert np.abs(result.theta - START).max() < 1e-12


def test_quantization_shows_encoder_counts_and_their_backward_difference():
    seen = []

    def record(t, theta, dtheta):
        seen.append((t, theta.copy(), dtheta.copy()))
        theta += 0.1                      # the controller's arrays: the next rate must not see this
        dtheta += 0.1
        return np.zeros(3)

    dtheta0 = np.array([0.2, -0.1, 0.3])
    result = simulate(START, 0.02, record, dtheta0=dtheta0, quantization=True)
    resolution = 2 * np.pi / (1024 * 4 * np.array([13.3, 11.6, 11.6]))
    times, theta, dtheta = (np.array(x) for x in zip(*seen))
    np.testing.assert_allclose(times, np.arange(21) / 1000, atol=1e-15)
    counts = theta / resolution
    np.testing.assert_allclose(counts, np.round(counts), atol=1e-9)
    assert np.all(np.abs(theta - result.theta) <= resolution / 2 + 1e-15)
    np.testing.assert_allclose(dtheta[1:], np.diff(theta, axis=0) * 1000, rtol=1e-9)
    before = np.round((START - dtheta0 / 1000) / resolution) * resolution
    np.testing.assert_allclose(dtheta[0], (theta[0] - before) * 1000, rtol=1e-9)


@pytest.mark.parametrize("arguments, message", [
    ({"theta0": [0.0, 0.0]}, "theta0: expected shape"),
    ({"theta0": [0.0, np.nan, 0.0]}, "theta0: contains NaN"),
    ({"theta0": np.zeros((2, 3))}, "theta0: expected one vector"),
    ({"dtheta0": [0.0, np.inf, 0.0]}, "dtheta0: contains NaN"),
    ({"duration": 0.0}, "duration: expected a finite number > 0"),
    ({"duration": np.inf}, "duration: expected a finite number > 0"),
    ({"duration": 1e-4}, "duration: .* shorter than one sample period"),
    ({"duration": 2000.0}, "duration: .* more than"),
    ({"rate": -1.0}, "rate: expected a finite number > 0"),
    ({"rate": "fast"}, "rate: expected a finite number > 0"),
    ({"controller": 3}, "controller: expected a callable"),
    ({"controller": lambda t, q, dq: [0.0, 0.0]}, r"controller: returned \[0.0, 0.0\] at t = 0 s"),
    ({"controller": lambda t, q, dq: [0.0, np.nan, 0.0] if t > 0.005 else [0.0] * 3}, "at t = 0.006 s"),
    ({"controller": lambda t, q, dq: None}, "controller: returned None"),
    ({"device": "mine"}, "device: expected a phantom_pin.Device"),
    ({"substeps": 0}, "substeps: expected an integer >= 1"),
])
def test_bad_arguments_are_named(arguments, message):
    call = {"theta0": START, "duration": 0.01, **arguments}
    with pytest.raises(InvalidInputError, match=message):
        simulate(**call)


def test_the_plant_is_phantom_forward_dynamics_with_friction_and_stops():
    """One RK4 substep of h from (theta, dtheta) equals RK4 of Phantom.forward_dynamics plus
    Device.friction and Device.stop_torque, at states inside and beyond the stops."""
    device = default_device()
    rng = np.random.default_rng(8)
    h = 1e-5
    for theta in rng.uniform(np.radians([-95, -40, -35]), np.radians([95, 125, 150]), (20, 3)):
        dtheta = rng.normal(0, 1, 3)
        if device.within_limits(theta) != device.within_limits(theta + dtheta * h):
            continue  # event bisection would split this step

        def rate(x):
            q, v = x[:3], x[3:]
            tau = device.stop_torque(q, v) - device.friction(v)
            return np.concatenate([v, device.phantom.forward_dynamics(q, v, tau)])

        x = np.concatenate([theta, dtheta])
        k1 = rate(x)
        k2 = rate(x + h / 2 * k1)
        k3 = rate(x + h / 2 * k2)
        k4 = rate(x + h * k3)
        expected = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        result = simulate(theta, h, dtheta0=dtheta, rate=1 / h, substeps=1)
        np.testing.assert_allclose(result.theta[-1], expected[:3], atol=1e-15)
        np.testing.assert_allclose(result.dtheta[-1], expected[3:], rtol=1e-10, atol=1e-12)


@pytest.mark.parametrize("duration, rate, stiffness, argument", [
    (1e300, 1e-300, None, "rate"), (10000.0, 0.001, None, "duration"), (100.0, 1000.0, 1e6, "duration")])
def test_work_beyond_a_few_minutes_is_refused_at_once(duration, rate, stiffness, argument):
    """The bound counts RK4 steps (periods x substeps), not samples: a huge period or a
    stiff stop is refused within a second, naming the argument and the stiffest term."""
    import time

    from phantom_pin import Device, Phantom, describe

    device = Device(Phantom(describe(overrides={"stops.stiffness": stiffness}))) if stiffness else None
    start = time.monotonic()
    with pytest.raises(InvalidInputError, match=f"^{argument}: .* RK4 steps .* more than 8e\\+06"):
        simulate(START, duration, rate=rate, device=device)
    assert time.monotonic() - start < 1.0


@pytest.mark.parametrize("flag", ["friction", "hard_stops", "saturation", "quantization"])
def test_flags_are_booleans(flag):
    """Before, friction="no" kept friction on (a truthy string)."""
    with pytest.raises(InvalidInputError, match=f"^{flag}: expected True(,| or) False.* got 'no'"):
        simulate(START, 0.01, **{flag: "no"})


def test_a_complex_torque_is_refused():
    """Before, NumPy dropped the imaginary part with a ComplexWarning."""
    with pytest.raises(InvalidInputError, match="^controller: returned"):
        simulate(START, 0.01, lambda t, theta, dtheta: np.array([1j, 0.0, 0.0]))


@pytest.mark.parametrize("kwargs, message", [
    ({"duration": 2**2000}, "^duration: expected a finite number > 0, got 1148130695"),    # was OverflowError
    ({"rate": 2**2000}, "^rate: expected a finite number > 0"),
    ({"duration": 1e306, "rate": 1e-306}, "^rate: 1e-306 Hz needs inf RK4 steps"),       # was OverflowError
    ({"controller": lambda t, q, v: ["1", "2", "3"]}, "^controller: returned \\['1'"),   # was read as numbers
    ({"controller": lambda t, q, v: np.array(["2020-01-01"] * 3, dtype="datetime64[D]")}, "^controller: returned"),
    ({"progress": 1}, "^progress: expected a callable"),                                  # was TypeError
    ({"substeps": 10**7}, "^substeps: 0.01 s at 1000 Hz needs 1e\\+08 RK4 steps"),        # was blamed on rate
    ({"rate": 1.0, "duration": 3.0, "substeps": 1}, "^substeps: 1 gives RK4 steps of 1 s at 1 Hz, longer than"),
])
def test_bad_arguments_are_refused_naming_them(kwargs, message):
    """Found by a bad-input pass: each raised something else or was silently accepted."""
    arguments = {"duration": 0.01, **kwargs}
    with pytest.raises(InvalidInputError, match=message):
        simulate(START, arguments.pop("duration"), arguments.pop("controller", None), **arguments)


def test_a_huge_finite_torque_is_a_number():
    """1e308 N m on each joint is finite (the check summed them and overflowed); it is clipped."""
    result = simulate(START, 0.002, lambda t, q, v: [1e308] * 3)
    assert result.tau_commanded[0, 0] == 1e308 and np.abs(result.tau).max() < 1.0


@pytest.mark.parametrize("kwargs, message", [
    ({"dtheta0": [1e6, 0.0, 0.0]},
     "^dtheta0: 1e\\+06 rad/s is far beyond any joint speed of the arm; the state diverged"),
    ({"controller": lambda t, theta, dtheta: np.array([1e300, 0.0, 0.0]), "saturation": False},
     "^controller: it applied up to 1e\\+300 N m with saturation off; the state diverged"),
    ({"theta0": [0.0, 1e6, 0.0]}, "^theta0: .* beyond the stops, more than a turn"),
])
def test_a_diverging_run_names_its_cause(kwargs, message):
    """Before: "theta: the mass matrix at [nan nan nan] is not positive definite"."""
    arguments = {"theta0": START, **kwargs}
    with pytest.raises(InvalidInputError, match=message):
        simulate(arguments.pop("theta0"), 0.05, arguments.pop("controller", None), **arguments)


@pytest.mark.parametrize("stiffness", [1e3, 1e4])
def test_the_default_substeps_resolve_a_stiff_stop(stiffness):
    """A fall onto an undamped stop of 1e3 or 1e4 N m/rad (stiffer than the shipped 10): the
    default substeps (from the stop's natural frequency, a joint on its own stop and the
    coupled one: 3 K) stay within 5e-7 rad of 8 times as many (measured 1.3e-7 and 1.5e-7;
    with K in place of 3 K, 1.3e-6 and 2.2e-6)."""
    from phantom_pin import Device, Phantom, describe

    device = Device(Phantom(describe(overrides={"stops.stiffness": stiffness, "stops.damping": 0.0})))
    theta0 = [0.0, -1.40, -0.45]
    run = simulate(theta0, 0.3, device=device, friction=False)
    finer = simulate(theta0, 0.3, device=device, friction=False, substeps=8 * run.substeps)
    assert not device.within_limits(run.theta).all()          # the stop was engaged
    assert np.abs(run.theta - finer.theta).max() < 5e-7


def test_sample_times_are_k_over_the_rate():
    """t[9] at 1 kHz is 0.009, not 9 * 0.001 = 0.009000000000000001, in the result and as the
    controller sees it."""
    seen = []
    result = simulate(START, 0.01, lambda t, theta, dtheta: seen.append(t) or np.zeros(3))
    assert result.t[9] == 0.009 and seen[9] == 0.009
    np.testing.assert_array_equal(result.t, np.arange(11) / 1000.0)


def test_simulate_holds_the_gimbal_where_it_is_asked_and_keeps_the_energy(six):
    """simulate(gimbal=) holds the gimbal at those angles: a 0.5 s free swing (no friction, no
    stops, no clipping) with the gimbal held at HELD keeps the total energy of the six-joint model
    built here at HELD within 1e-8 of its swing's kinetic energy at every sample (RK4's error);
    evaluated at locked_at instead it drifts by more than 1e-4 of it, so the run used HELD.
    Gimbal angles outside the gimbal's range are refused by name."""
    result = simulate([0.2, 0.3, 0.5], 0.5, None, friction=False, hard_stops=False, saturation=False,
                      device=Device(Phantom.from_model("touch")), gimbal=HELD, substeps=4)
    energy = np.array([six.energy(q, HELD, v) for q, v in zip(result.theta, result.dtheta)])
    kinetic = max(0.5 * v @ six.mass(q, HELD) @ v for q, v in zip(result.theta, result.dtheta))
    assert kinetic > 1e-3
    assert np.abs(energy - energy[0]).max() < 1e-8 * kinetic
    elsewhere = np.array([six.energy(q, None, v) for q, v in zip(result.theta, result.dtheta)])
    assert np.abs(elsewhere - elsewhere[0]).max() > 1e-4 * kinetic
    with pytest.raises(InvalidInputError, match=r"^gimbal: joint6 at 9.0 rad is outside its range"):
        simulate([0.2, 0.3, 0.5], 0.01, device=Device(Phantom.from_model("touch")), gimbal=[0.0, 0.0, 9.0])


@pytest.mark.parametrize("arguments, name", [
    ({"dtheta0": [1e6, 0.0, 0.0]}, "dtheta0"),                                     # rad/s
    ({"controller": lambda t, q, v: np.array([1e300, 0.0, 0.0]), "saturation": False}, "controller"),
])
def test_a_diverging_run_names_its_cause_in_the_field(arguments, name):
    with pytest.raises(InvalidInputError) as raised:
        simulate([0.0, 0.3, 0.4], 0.05, **arguments)
    assert raised.value.argument == name and "the state diverged" in raised.value.detail


def test_quantization_without_an_encoder_names_the_option():
    with pytest.raises(MissingDataError) as raised:
        simulate([0.2, 0.6, 0.8], 0.01, device=Device.from_model("touch"), quantization=True)
    assert raised.value.argument == "quantization"
