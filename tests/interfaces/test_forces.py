"""The force path without ROS (phantom_pin.interfaces.forces, ros2.DriverBridge; the profiles' own
tests are test_profiles.py): each driver's joint_states read as the driver writes them (its source
lines, driver_reference), the force it is sent taken back to OpenHaptics' frame by its own formula,
and J^T F compared with the Touch's gravity from the report's closed form and the gimbal's reference
load (J from complex steps of Ubitrack's kinematics): 1e-9 N m."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from helpers import PROFILES, message
from phantom_pin import InvalidInputError, Phantom
from phantom_pin.config.types import Friction
from phantom_pin.interfaces import profiles
from phantom_pin.interfaces.forces import SINGULAR, Renderer
from phantom_pin.interfaces.ros2.node import DriverBridge, fill_force
from references import driver as ref


@pytest.fixture(scope="module")
def touch() -> Phantom:
    return Phantom.from_model("touch")


@pytest.mark.parametrize("name", PROFILES)
def test_the_drivers_joint_states_give_theta_and_the_raw_gimbal(touch, name):
    """Each driver's published angles (its formulas) back to theta = (-a1, a2, a3) and g: 1e-12."""
    bridge = DriverBridge(touch, profiles.load(name))
    theta, g = ref.states(50, seed=11)
    for t, gg in zip(theta, g):
        a = np.array([-t[0], t[1], t[2]])
        names, positions = ref.published(name, a, gg)
        shuffled = [*names[::-1], "other"]
        values = dict(zip(names, positions))
        got_theta, got_g = bridge.state(shuffled, [values.get(n, 9.0) for n in shuffled])
        assert np.abs(got_theta - t).max() < 1e-12 and np.abs(got_g - gg).max() < 1e-12


@pytest.mark.parametrize("name", PROFILES)
def test_the_force_sent_holds_gravity_plus_the_users_force(touch, name):
    """F in the driver's message, taken back by the driver's own formula: J^T F = G(theta, g) +
    J^T F_user (1e-9 N m), F_user 0.3 N given in base_link and in the stylus frame; where the
    driver's clamp acts, |F| is the clamp and F keeps its direction."""
    profile = profiles.load(name)
    bridge = DriverBridge(touch, profile)
    report = touch.config.report
    theta, g = ref.states(40, seed=12)
    user = np.array([0.1, -0.2, 0.3]) * 0.5
    clamped = 0
    for t, gg in zip(theta, g):
        for frame, f_s in (("base_link", ref.BASE_FROM_S.T @ user), ("stylus", ref.stylus_rotation(t, gg) @ user)):
            rendered = bridge.renderer(t, gg, bridge.user_force(frame, user, t, gg))
            sent = message(profile)
            fill_force(sent, profile, rendered.message)
            force = ref.FORCE[name](sent)
            jacobian = ref.tip_jacobian(t)
            want = ref.gravity(t, gg, report) + jacobian.T @ f_s
            if rendered.scale == 1.0:
                assert np.abs(jacobian.T @ force - want).max() < 1e-9
            else:  # the driver's clamp: the size it allows, the direction of the unclamped force
                clamped += 1
                assert np.linalg.norm(force) == pytest.approx(profile.force.clamp, rel=1e-12)
                unclamped = np.linalg.solve(jacobian.T, want)
                assert np.abs(force / np.linalg.norm(force) - unclamped / np.linalg.norm(unclamped)).max() < 1e-9
    if profile.force.clamp == np.inf:
        assert clamped == 0


def test_the_clamp_is_the_lowest_of_the_drivers_max_force_and_the_motors(touch):
    """A 50 N user force: saw's 2 N, --max-force 1 N, and the motors' saturation torques
    (config/touch/actuation.yaml: 0.8801, 0.4401, 0.4401 N m) each bound it; never exceeded."""
    limits = np.array([0.8801, 0.4401, 0.4401])
    theta, g = ref.states(30, seed=13)
    for name, max_force, cap in (("sawsensablephantom", np.inf, 2.0), ("touch_ros2_control", 1.0, 1.0),
                                 ("geomagic_touch_x_ros2", np.inf, np.inf)):
        renderer = Renderer(touch, profiles.load(name), max_force=max_force)
        for t, gg in zip(theta, g):
            rendered = renderer(t, gg, (50.0, -20.0, 10.0))
            torques = ref.tip_jacobian(t).T @ rendered.openhaptics
            assert rendered.scale < 1 and np.all(np.abs(torques) <= limits * (1 + 1e-12))
            assert np.linalg.norm(rendered.openhaptics) <= cap * (1 + 1e-12)
            assert np.isclose(np.linalg.norm(rendered.openhaptics), cap, rtol=1e-12) or \
                np.isclose(np.abs(torques / limits).max(), 1.0, rtol=1e-12)


def test_near_the_singularity_the_inverse_is_damped_and_the_force_finite(touch):
    """The tip on joint 1's axis (x = z = 0 in frame s: l1 cos(theta2) + l2 sin(theta3) = 0):
    J loses joint 1's column; the force stays finite, bounded by |G| / (2 SINGULAR) at most."""
    renderer = Renderer(touch, profiles.load("geomagic_touch_x_ros2"))
    theta3 = -np.arcsin(np.cos(1.2))            # l1 = l2
    theta = np.array([0.3, 1.2, theta3])
    rendered = renderer(theta, None, (0.0, 0.0, 0.0))
    assert rendered.singular and rendered.sigma_min < 1e-12 and np.isfinite(rendered.openhaptics).all()
    assert np.linalg.norm(rendered.openhaptics) <= np.linalg.norm(touch.gravity(theta)) / (2 * SINGULAR)
    far = renderer(np.array([0.3, 0.5, 0.6]), None)
    assert not far.singular and far.sigma_min > SINGULAR


def test_friction_compensation_adds_the_law_at_the_filtered_rate(touch):
    """A joint path at a constant rate (rad/s), sampled at 1 kHz: after 0.5 s the filtered rate is
    the true one (the first-order filter's error e^-63) and J^T F = G + viscous w + Coulomb sign(w)
    (config/touch/actuation.yaml: 5e-4 N m s/rad, 0.01 N m) within 1e-9 N m; at rest no Coulomb term."""
    renderer = Renderer(touch, profiles.load("geomagic_touch_x_ros2"), compensate=("gravity", "friction"))
    rate = np.array([0.4, -0.3, 0.2])
    start = np.array([0.0, 0.4, 0.5])
    for k in range(501):
        t = start + rate * k * 1e-3
        rendered = renderer(t, None, (0.0, 0.0, 0.0), time=k * 1e-3)
    want = ref.gravity(t, np.zeros(3), touch.config.report) + 5e-4 * rate + 0.01 * np.sign(rate)
    assert np.abs(ref.tip_jacobian(t).T @ rendered.openhaptics - want).max() < 1e-9
    still = Renderer(touch, profiles.load("geomagic_touch_x_ros2"), compensate=("gravity", "friction"))
    for k in range(3):
        rendered = still(start, None, time=k * 1e-3)
    assert np.abs(ref.tip_jacobian(start).T @ rendered.openhaptics
                  - ref.gravity(start, np.zeros(3), touch.config.report)).max() < 1e-9


@pytest.mark.parametrize("call, argument", [
    (lambda r: r([0.1, np.nan, 0.2]), "theta"),
    (lambda r: r([0.1, 0.2, 0.3], [0, np.inf, 0]), "gimbal"),
    (lambda r: r([0.1, 0.2, 0.3], None, (1e300, 0, 0)), "user"),
    (lambda r: r([0.1, 0.2]), "theta"),
])
def test_bad_states_are_refused_naming_the_argument(touch, call, argument):
    renderer = Renderer(touch, profiles.load("sawsensablephantom"))
    with pytest.raises(InvalidInputError) as error:
        call(renderer)
    assert error.value.argument == argument


def test_bad_options_and_messages_are_refused_naming_them(touch):
    profile = profiles.load("sawsensablephantom")
    for kwargs, argument in (({"compensate": ("wind",)}, "compensate"), ({"compensate": "gravity"}, "compensate"),
                             ({"compensate": ("gravity", "inertia")}, "kappa"), ({"kappa": 0.5}, "kappa"),
                             ({"compensate": ("inertia",), "kappa": 1.0}, "kappa"),
                             ({"compensate": ("gravity", "friction"), "friction": Friction((0.0,) * 3, (0.0,) * 3)},
                              "compensate"),
                             ({"max_force": 0.0}, "max_force"), ({"max_force": float("nan")}, "max_force")):
        with pytest.raises(InvalidInputError) as error:
            Renderer(touch, profile, **kwargs)
        assert error.value.argument == argument
    with pytest.raises(InvalidInputError) as error:
        profiles.load("omni_firewire")
    assert error.value.argument == "driver"
    bridge = DriverBridge(touch, profile)
    names = ["waist", "shoulder", "elbow", "yaw", "pitch", "roll"]
    for frame, force, argument in (("nowhere", (0, 0, 1), "frame_id"), ("", (0, np.nan, 0), "force"),
                                   ("stylus", (1e9, 0, 0), "force")):
        with pytest.raises(InvalidInputError) as error:
            bridge.wrench(frame, force)
        assert error.value.argument == argument
    for given, positions, argument in ((names + ["waist"], [0.1] * 7, "name"), (names[:5], [0.1] * 5, "name"),
                                       (names, [0.1] * 5, "position"), (names, [0.1, np.nan, 0, 0, 0, 0], "position"),
                                       (names, [9.0, 0.2, 0.1, 0, 0, 0], "position")):
        with pytest.raises(InvalidInputError) as error:
            bridge.state(given, positions)
        assert error.value.argument == argument
    with pytest.raises(InvalidInputError) as error:
        bridge.state(names, [0.1] * 6, [0.0] * 5)
    assert error.value.argument == "velocity"
    assert bridge.state(names, [0.1] * 6, [0.0] * 6)[0].shape == (3,)


def test_the_relay_sends_the_same_numbers_as_a_vector3_beside_the_drivers_topic(touch):
    """--relay: the geomagic driver's numbers (its swapped frame) as geometry_msgs/Vector3 on
    /phantom/force_feedback_relay; the relay of docs/drivers.md copies them into OmniFeedback."""
    profile = profiles.load("geomagic_touch_ros2")
    relayed = profiles.relayed(profile)
    assert (relayed.force.topic, relayed.force.type) == ("/phantom/force_feedback_relay", "geometry_msgs/msg/Vector3")
    theta, g = ref.states(5, seed=14)
    for t, gg in zip(theta, g):
        direct, relay = DriverBridge(touch, profile).renderer(t, gg), DriverBridge(touch, relayed).renderer(t, gg)
        vector = message(relayed)
        fill_force(vector, relayed, relay.message)
        omni = SimpleNamespace(force=vector)     # what the relay publishes
        assert np.array_equal(ref.FORCE["geomagic_touch_ros2"](omni), direct.openhaptics)


# -- what the mutation survivors of ../shared/data/mutants6.md got past (each against a reference) --
@pytest.mark.parametrize("name", PROFILES)
def test_the_relay_of_every_driver_fills_a_bare_vector3_with_a_stamp_given(touch, name):
    """Mutant 06. --relay sends geometry_msgs/Vector3, which has no header, whatever the driver's
    own type: filled with the state's stamp given (as the node does), the bare Vector3 (x, y, z
    only) takes the three numbers, and the driver's own formula of them (driver_reference.FORCE,
    the relay copying them into its message) gives the direct path's HD_CURRENT_FORCE, exactly."""
    profile = profiles.load(name)
    relayed = profiles.relayed(profile)
    theta, g = ref.states(3, seed=15)
    for t, gg in zip(theta, g):
        direct, relay = Renderer(touch, profile)(t, gg), Renderer(touch, relayed)(t, gg)
        vector = SimpleNamespace(x=0.0, y=0.0, z=0.0)
        fill_force(vector, relayed, relay.message, stamp=SimpleNamespace(sec=1, nanosec=2))
        own = message(profile)
        target = own if profile.force.field is None else own.force if profile.force.field == "force" \
            else own.wrench.force
        target.x, target.y, target.z = vector.x, vector.y, vector.z
        assert set(vars(vector)) == {"x", "y", "z"}
        assert np.array_equal(ref.FORCE[name](own), direct.openhaptics)


def test_the_inverse_is_exact_wherever_the_jacobian_is_well_conditioned(touch):
    """Mutant 07. Postures whose smallest singular value of the tip's Jacobian (complex steps of
    Ubitrack's kinematics, numpy's SVD) lies between 3 and 15 mm/rad, above SINGULAR's 2 mm/rad
    (a lever of 1.5 % of the arm: nothing is near singular there): J^T F equals the closed form's
        gravity within 1e-9 N m, undamped. 10 seeded postures inside the stops with the tip 4-14 mm
    from joint 1's axis (the arm folded up near joint 2's and the coupled stop: the Touch's only
    postures that near it) whose singular value lies in that band."""
    rng = np.random.default_rng(16)
    _, g = ref.states(10, seed=16)
    kept = []
    while len(kept) < 10:    # the tip r from joint 1's axis: l1 cos(theta2) + l2 sin(theta3) = r
        theta2, r = rng.uniform(1.74, 1.75), rng.uniform(0.004, 0.014)
        theta3 = np.pi - np.arcsin((r - ref.L1 * np.cos(theta2)) / ref.L2)
        t = np.array([rng.uniform(-0.9, 0.9), theta2, theta3])
        inside = (t[2] <= ref.LIMITS["joint3"]["upper"] and t[1] <= ref.LIMITS["joint2"]["upper"]
                  and t[2] - t[1] <= ref.LIMITS["theta3_minus_theta2_max"])
        if inside and 0.003 < np.linalg.svd(ref.tip_jacobian(t), compute_uv=False)[-1] < 0.015:
            kept.append((t, g[len(kept)]))
    renderer = Renderer(touch, profiles.load("geomagic_touch_x_ros2"))
    for t, gg in kept:
        rendered = renderer(t, gg)
        want = ref.gravity(t, gg, touch.config.report)
        assert np.abs(ref.tip_jacobian(t).T @ rendered.openhaptics - want).max() < 1e-9


def test_a_joint_resting_with_encoder_jitter_gets_no_coulomb_push(touch):
    """Mutant 10. A resting arm whose angles jitter by +-1e-6 rad sample to sample (1 kHz: raw
    rates of 2e-3 rad/s, below forces.REST) is at rest: pushing it with the Coulomb torque (0.01
    N m, config/touch/actuation.yaml) would start it moving. J^T F is gravity (closed form) plus
    the viscous term of the filtered rate only (5e-4 N m s/rad x at most 2e-3 rad/s = 1e-6 N m),
    within 2e-6 N m, far below the 0.01 N m a Coulomb term adds."""
    renderer = Renderer(touch, profiles.load("geomagic_touch_x_ros2"), compensate=("gravity", "friction"))
    start = np.array([0.1, 0.4, 0.5])
    for k in range(200):
        t = start + (1e-6 if k % 2 else 0.0)
        rendered = renderer(t, None, time=k * 1e-3)
        want = ref.gravity(t, np.zeros(3), touch.config.report)
        assert np.abs(ref.tip_jacobian(t).T @ rendered.openhaptics - want).max() < 2e-6


def test_the_renderers_inertia_and_friction_are_the_servo_loops(touch):
    """The ROS 2 renderer with gravity, friction and kappa = 0.4 of the inertia, fed a stamped
    1 kHz motion of the Touch, puts on the joints (J^T F_comp) what the pyOpenHaptics Compensator
    computes from the same angles, tick by tick (1e-9 N m): the two servo paths share one
    estimator and one law, written twice as terms."""
    from phantom_pin import Device
    from phantom_pin.interfaces.openhaptics import Compensator
    device = Device(touch)
    renderer = Renderer(touch, profiles.load("sawsensablephantom"), ("gravity", "friction", "inertia"), kappa=0.4)
    compensate = Compensator("touch", "joint_torque", ("gravity", "friction", "inertia"), kappa=0.4)
    sign = np.array([-1.0, 1.0, 1.0])
    for k in range(300):
        t = k / 1000.0
        theta = np.array([0.1, 0.4, 0.5]) + 0.15 * np.sin(2 * np.pi * np.array([1.0, 1.3, 0.7]) * t)
        rendered = renderer(theta, time=t)
        applied = device.tip_jacobian(theta).T @ rendered.compensation
        expected = compensate.torque(sign * theta)
        assert np.abs(applied - expected).max() <= 1e-9
