"""Device: stops, friction, motors and encoders against the published numbers, typed here
from their sources (../shared/data/phantom_premium_1_5.md: mahilab/Phantom and maxon's data
sheet of the RE 25 118743), and against the closed form (gravity, kinematics)."""

import math
import shutil

import numpy as np
import pytest

from helpers import REPORT
from phantom_pin import (
    Device,
    InvalidInputError,
    ParameterFileError,
    Phantom,
    closed_form,
    config,
)
from phantom_pin.config import MODELS

CONFIG_DIR = MODELS["premium_1_5"].config

DEG = math.pi / 180
#: mahilab/Phantom's stops (deg): per joint, and the parallelogram's coupled ones.
STOPS_DEG = {"q1": (-90, 90), "q2": (-124, 119), "q3": (-29, 214), "q2-q3": 65, "q3-q2": 55}
K_STOP, B_STOP = 10.0, 0.1                       # N m/rad, N m s/rad (mahilab's hard stop)
VISCOUS, COULOMB = 5e-4, 0.01                    # N m s/rad, N m (mahilab's; its tanh(10 q') smoothing not kept)
KT, I_NOMINAL, TAU_NOMINAL = 23.4e-3, 1.24, 28.6e-3   # N m/A, A, N m (data sheet)
I_STALL, TAU_STALL = 5.5, 129e-3                 # A, N m (data sheet)
RATIOS = np.array([13.3, 11.6, 11.6])            # the report (docs/errata.md E15)
ENCODER_CPR, QUADRATURE = 1024, 4                # HEDM-5500, decoded X4


@pytest.fixture(scope="module")
def device(phantom):
    return Device(phantom)


def test_device_wraps_the_phantom_and_builds_one_by_default(phantom):
    assert Device(phantom).phantom is phantom
    assert Device().phantom.config == phantom.config
    touch = Device.from_model("touch")
    assert touch.config.name == "touch" and touch.phantom.description is Phantom.from_model("touch").description
    with pytest.raises(InvalidInputError) as error:
        Device.from_model("nope")
    assert error.value.argument == "model"


def test_the_plain_call_refuses_what_is_not_a_phantom(tmp_path):
    """Device(name), Device(description), Device(folder) and anything else but a Phantom are
    refused with InvalidInputError naming ``phantom`` and the call that makes the device."""
    from phantom_pin import describe

    description = describe("touch")
    for bad, call in (("touch", "Device.from_model('touch')"), (description, "Device(Phantom(description))"),
                      (tmp_path, "Device(Phantom.from_folder(path))"),
                      (str(tmp_path), "Device(Phantom.from_folder(path))"),
                      (42, "Device.from_model(model)"), ("not a phantom", "Device.from_model(model)")):
        with pytest.raises(InvalidInputError) as error:
            Device(bad)
        assert error.value.argument == "phantom" and call in error.value.detail, (bad, error.value.detail)
    assert len(str(error.value)) < 300  # a Description is named, not printed with its texts


# -- stops -----------------------------------------------------------------------------
def _state(q1=0.0, q2=30.0, q3=40.0):
    return np.radians([q1, q2, q3])


@pytest.mark.parametrize("name, inside, outside", [
    # per joint, with the other angles chosen so that the coupled stops hold
    ("q1 lower", _state(q1=-89.9), _state(q1=-90.1)),
    ("q1 upper", _state(q1=89.9), _state(q1=90.1)),
    ("q2 upper", _state(q2=118.9, q3=120), _state(q2=119.1, q3=120)),
    ("q3 lower", _state(q2=0, q3=-28.9), _state(q2=0, q3=-29.1)),
    # the parallelogram
    ("q2 - q3 <= 65", _state(q2=64.9, q3=0), _state(q2=65.1, q3=0)),
    ("q3 - q2 <= 55", _state(q2=0, q3=54.9), _state(q2=0, q3=55.1)),
    ("q3 - q2 <= 55, raised", _state(q2=60, q3=114.9), _state(q2=60, q3=115.1)),
])
def test_within_limits_on_both_sides_of_each_stop(device, name, inside, outside):
    assert device.within_limits(inside) is True
    assert device.within_limits(outside) is False


def test_loose_joint_stops_are_unreachable_through_the_parallelogram(device):
    """q2 >= -124 deg and q3 <= 214 deg never bind: q3 >= -29 and q3 - q2 <= 55 give
    q2 >= -84 deg; q3 - q2 <= 55 and q2 <= 119 give q3 <= 174 deg."""
    assert not device.within_limits(_state(q2=-123.9, q3=-29)) and not device.within_limits(_state(q2=-84.1, q3=-29))
    assert device.within_limits(_state(q2=-83.9, q3=-29)) and device.within_limits(_state(q2=119, q3=174))
    assert not device.within_limits(_state(q2=119, q3=174.1))


def test_within_limits_of_a_batch_is_an_array(device):
    batch = np.stack([_state(), _state(q1=95), _state(q2=0, q3=60)])
    result = device.within_limits(batch)
    assert isinstance(result, np.ndarray) and result.dtype == bool and result.tolist() == [True, False, False]
    with pytest.raises(InvalidInputError, match="theta"):
        device.within_limits([0.0, np.nan, 0.0])


def test_stop_torque_is_mahilabs_where_one_stop_engages(device):
    theta, rate = _state(q1=95), np.array([0.3, 0.0, 0.0])
    expected = K_STOP * (90 * DEG - theta[0]) - B_STOP * rate[0]   # tau = K (limit - q) - B q'
    np.testing.assert_allclose(device.stop_torque(theta, rate), [expected, 0, 0], rtol=1e-12)
    # coupled: q2's interval is [.., q3 + 65 deg]; the reaction on q3 is equal and opposite
    theta, rate = _state(q2=70, q3=0), np.array([0.0, 0.4, 0.0])
    expected = K_STOP * (theta[2] + 65 * DEG - theta[1]) - B_STOP * rate[1]
    np.testing.assert_allclose(device.stop_torque(theta, rate), [0, expected, -expected], rtol=1e-12)
    assert not device.stop_torque(_state(), [1.0, 2.0, 3.0]).any()


def test_stop_torque_is_minus_the_gradient_of_the_stop_energy_and_damps(device):
    rng = np.random.default_rng(12)
    theta = rng.uniform(np.radians([-100, -60, -40]), np.radians([100, 130, 200]), (300, 3))
    rate = rng.normal(0, 2, (300, 3))
    spring = device.stop_torque(theta, np.zeros(3) * theta)
    step = 1e-7
    for j in range(3):
        shift = np.zeros(3)
        shift[j] = step
        gradient = (device.stop_energy(theta + shift) - device.stop_energy(theta - shift)) / (2 * step)
        np.testing.assert_allclose(spring[:, j], -gradient, atol=1e-6)  # N m
    damping = device.stop_torque(theta, rate) - spring
    assert np.all(np.einsum("ni,ni->n", damping, rate) <= 1e-15)  # power of the dampers <= 0
    assert (device.stop_energy(theta) > 0).sum() > 100               # the sample hits stops


# -- friction --------------------------------------------------------------------------
def test_sliding_friction_is_viscous_plus_coulomb_and_opposes_motion(device):
    """In motion: mahilab's viscous and Coulomb coefficients, the Coulomb term at its full level
    at any rate (no smoothing); at rest 0 (the stick torque depends on the load: simulate)."""
    rate = np.random.default_rng(3).normal(0, 1, (200, 3))
    expected = VISCOUS * rate + COULOMB * np.where(rate > 0, 1.0, -1.0)
    np.testing.assert_allclose(device.friction(rate), expected, rtol=1e-14)
    np.testing.assert_allclose(device.friction([1e-9, -1e-9, 0.0]), [COULOMB, -COULOMB, 0.0], rtol=1e-6)
    assert np.all(device.friction(rate) * rate >= 0)   # removes power: -tau_f . dtheta <= 0
    np.testing.assert_array_equal(device.friction([0.0, 0.0, 0.0]), 0.0)


# -- motors ----------------------------------------------------------------------------
def test_motor_limits_are_the_data_sheet_torques_through_the_ratios(device, phantom):
    np.testing.assert_allclose(device.continuous_torque, TAU_NOMINAL * RATIOS, rtol=1e-15)
    np.testing.assert_allclose(device.peak_torque, TAU_STALL * RATIOS, rtol=1e-15)
    np.testing.assert_allclose(phantom.model.effortLimit, device.continuous_torque, rtol=1e-12)  # URDF effort


def test_currents_and_torques_round_trip_against_the_data_sheet(device):
    # stall: 5.5 A x 23.4 mN m/A = 128.7 mN m, the data sheet's 129 within its rounding (+-0.5)
    stall = device.joint_torques([I_STALL] * 3) / RATIOS
    assert np.all(np.abs(stall - TAU_STALL) <= 0.5e-3)
    np.testing.assert_allclose(device.motor_currents(TAU_STALL * RATIOS), TAU_STALL / KT, rtol=1e-14)
    # nominal: 28.6 mN m needs 1.222 A, 1.4 % below the rated 1.24 A (the data sheet's nominal
    # torque is the shaft torque, net of the motor's own friction, so Kt I_N exceeds it)
    nominal = device.motor_currents(device.continuous_torque)
    assert np.all((nominal < I_NOMINAL) & (nominal > 0.98 * I_NOMINAL))
    tau = np.random.default_rng(4).normal(0, 0.3, (100, 3))
    np.testing.assert_allclose(device.joint_torques(device.motor_currents(tau)), tau, rtol=1e-14)
    np.testing.assert_allclose(device.motor_currents(tau), tau / (RATIOS * KT), rtol=1e-14)


def test_available_torque_is_the_limit_minus_gravity(device, states):
    theta = states[0]
    gravity = closed_form.gravity(theta, REPORT)
    for continuous, limit in ((True, TAU_NOMINAL * RATIOS), (False, TAU_STALL * RATIOS)):
        lower, upper = device.available_torque(theta, continuous=continuous)
        np.testing.assert_allclose(lower, -limit - gravity, atol=1e-12)
        np.testing.assert_allclose(upper, limit - gravity, atol=1e-12)


def _position_jacobian(theta, step=1e-6):
    """d(tip position)/d(theta) by central differences of the closed form (eq. 10)."""
    columns = []
    for j in range(3):
        shift = np.zeros(3)
        shift[j] = step
        columns.append((closed_form.forward_kinematics(theta + shift, REPORT)[..., :3, 3]
                        - closed_form.forward_kinematics(theta - shift, REPORT)[..., :3, 3]) / (2 * step))
    return np.stack(columns, axis=-1)


def test_tip_jacobian_is_the_derivative_of_eq_10(device, states):
    theta = states[0][:50]
    np.testing.assert_allclose(device.tip_jacobian(theta), _position_jacobian(theta), atol=1e-9)  # m/rad


def test_tip_force_capacity_reaches_exactly_one_motor_limit(device, states):
    theta = states[0][:50]
    direction = np.random.default_rng(5).normal(size=(50, 3))
    force = device.tip_force_capacity(theta, direction)
    unit = direction / np.linalg.norm(direction, axis=1, keepdims=True)
    motor = (np.einsum("nji,nj->ni", _position_jacobian(theta), force[:, None] * unit)
             + closed_form.gravity(theta, REPORT))
    margin = np.abs(motor) / (TAU_NOMINAL * RATIOS)
    assert np.all(margin <= 1 + 1e-8) and np.all(np.abs(margin.max(axis=1) - 1) < 1e-8)
    assert np.all(force > 0.5)  # N: the box is far from where gravity alone saturates a motor
    with pytest.raises(InvalidInputError, match="direction"):
        device.tip_force_capacity(theta[0], [0.0, 0.0, 0.0])


# -- encoders --------------------------------------------------------------------------
def test_encoder_resolution_counts_and_tip_resolution(device, states):
    resolution = 2 * np.pi / (ENCODER_CPR * QUADRATURE * RATIOS)   # rad per count
    np.testing.assert_allclose(device.encoder_resolution, resolution, rtol=1e-15)
    np.testing.assert_array_equal(device.encoder_counts(2 * np.pi / RATIOS), [4096, 4096, 4096])  # one motor turn
    np.testing.assert_array_equal(device.encoder_counts([0.0, 0.0, 0.0]), [0, 0, 0])
    theta = states[0]
    counts = device.encoder_counts(theta)
    assert counts.dtype == np.int64
    assert np.all(np.abs(device.encoder_theta(counts) - theta) <= resolution / 2 * (1 + 1e-12))
    np.testing.assert_allclose(device.tip_resolution(theta[:20]),
                               np.linalg.norm(_position_jacobian(theta[:20]), axis=1) * resolution, rtol=1e-7)


# -- parameters ------------------------------------------------------------------------
def test_shipped_device_numbers_and_sources(device):
    friction, stops, sources = device.config.actuation.friction, device.config.limits.stops, device.config.sources
    assert (friction.viscous, friction.coulomb) == ((VISCOUS,) * 3, (COULOMB,) * 3)
    assert (stops.stiffness, stops.damping) == (K_STOP, B_STOP)
    np.testing.assert_allclose(stops.lower, np.radians([-90, -124, -29]), rtol=1e-15)
    np.testing.assert_allclose(stops.upper, np.radians([90, 119, 214]), rtol=1e-15)
    np.testing.assert_allclose([stops.coupled.theta2_minus_theta3_max, stops.coupled.theta3_minus_theta2_max],
                               np.radians([65, 55]), rtol=1e-15)
    assert set(sources) == {"transmission_ratio", "motor", "encoder", "friction", "stops"}
    assert "118743" in sources["motor"] and "mahilab" in sources["stops"]


@pytest.mark.parametrize("file, old, new, message", [
    ("actuation.yaml", "  coulomb: 0.01", "  coulomb: -0.01", "friction.coulomb must not be negative"),
    ("actuation.yaml", "  torque_constant: 0.0234", "  torque_constant: 0", "motor.torque_constant must be positive"),
    ("actuation.yaml", "  counts_per_cycle: 4.0", "  counts: 4.0", "missing key encoder.counts_per_cycle"),
    ("joint_limits.yaml", "  stiffness: 10.0", "  stiffness: .nan", "stops.stiffness must be a finite"),
    ("joint_limits.yaml", "  joint3: {lower: -0.5061454830783556", "  joint3: {lower: 4.0",
     "stops.joint3.lower must be below"),
    ("joint_limits.yaml", "  stops: \"mahilab", "  stop: \"mahilab", "missing key sources.stops"),
    ("joint_limits.yaml", "  stops: \"mahilab", "  stops: \"\" # \"mahilab", "sources.stops must be a non-empty text"),
])
def test_malformed_device_numbers_are_named(tmp_path, file, old, new, message):
    folder = tmp_path / "config"
    shutil.copytree(CONFIG_DIR, folder)
    text = (folder / file).read_text()
    assert old in text
    (folder / file).write_text(text.replace(old, new, 1))
    with pytest.raises(ParameterFileError, match=message) as error:
        config.read(folder)
    assert file in str(error.value)


def test_device_reads_its_config_folder(tmp_path, phantom):
    """Device(Phantom.from_folder(DIR)) takes the device numbers of DIR, the folder the rigid
    body comes from; Device(DIR) is refused naming that way (one input type per way of making
    it); a phantom and a folder together are refused (no config_dir keyword any more)."""
    folder = tmp_path / "config"
    shutil.copytree(CONFIG_DIR, folder)
    text = (folder / "actuation.yaml").read_text()
    (folder / "actuation.yaml").write_text(text.replace("  viscous: 5.0e-4", "  viscous: 2.0e-3", 1))
    device = Device(Phantom.from_folder(folder))
    np.testing.assert_allclose(device.friction([1.0, 0.0, 0.0]), [2e-3 + COULOMB, 0, 0], rtol=1e-14)
    with pytest.raises(InvalidInputError, match=r"Device\(Phantom.from_folder\(path\)\)") as error:
        Device(folder)
    assert error.value.argument == "phantom"
    with pytest.raises(TypeError):
        Device(phantom, folder)
    with pytest.raises(TypeError, match="config_dir"):
        Device(config_dir=folder)


def test_reachable_is_forward_kinematics_inside_the_stops(device):
    """Every tip of a posture inside the stops is reachable (eq. 10 against the inverse
    kinematics of Device.reachable); beyond l1 + l2, and straight behind the shoulder where
    only theta2 > 119 deg would reach, nothing is."""
    rng = np.random.default_rng(21)
    p = device.config.kinematics
    stops = device.config.limits.stops
    theta = rng.uniform(stops.lower, stops.upper, (6000, 3))
    theta = theta[device.within_limits(theta)]
    assert len(theta) > 1000
    assert device.reachable(closed_form.forward_kinematics(theta, REPORT)[:, :3, 3]).all()
    shoulder = np.array([0.0, p.l2, -p.l1])  # frame s (eqs 4-5)
    assert not device.reachable(shoulder + [0.0, 0.0, p.l1 + p.l2 + 1e-3])
    assert device.reachable(shoulder + [0.0, 0.0, 0.3])        # 0.3 m in front, at shoulder height
    assert not device.reachable(shoulder + [0.0, 0.0, -0.3])   # 0.3 m behind: needs theta2 >= 146 deg
    assert device.reachable(shoulder + [[0.0, 0.0, 0.3], [0.0, 0.0, -0.3]]).tolist() == [True, False]
    grid = shoulder + np.array([[[0.0, 0.0, 0.3], [0.0, 0.0, -0.3]]] * 2)        # (2, 2, 3): before, (4,)
    assert device.reachable(grid).tolist() == [[True, False]] * 2


@pytest.mark.parametrize("call, argument", [
    (lambda d: d.encoder_counts([1e16, 0, 0]), "theta"),       # int64 overflow, before: -2**63
    (lambda d: d.motor_currents([1e308, 0, 0]), "tau"),         # before: inf
    (lambda d: d.joint_torques([1e308, 0, 0]), "currents"),
    (lambda d: d.stop_energy([1e200, 0, 0]), "theta"),
    (lambda d: d.tip_force_capacity([[0.1, 0.3, 0.4]] * 2, [[0.0, 1.0, 0.0]] * 3), "theta"),  # before: NumPy's error
    (lambda d: d.stop_torque([1e308, 0, 0], [0, 0, 0]), "theta, dtheta"),       # before: -inf, nan, nan
    (lambda d: d.available_torque([0.1, 0.3, 0.4], None), "continuous"),        # before: the peak torque
    (lambda d: d.tip_force_capacity([0.1, 0.3, 0.4], [0, 0, 1], "yes"), "continuous"),  # before: continuous
])
def test_huge_or_mismatched_input_is_refused_naming_the_argument(device, call, argument):
    with pytest.raises(InvalidInputError, match=f"^{argument}"):
        call(device)


def test_tip_force_capacity_of_a_huge_direction_and_along_the_straight_arm(device):
    """The direction is normalised without overflow (1e308 components: before, inf N); a force
    along the straight arm (theta3 - theta2 = 90 deg, through the shoulder) loads no joint and
    is carried by the structure: inf (before: 4.4e15 N from rounding)."""
    theta = np.array([0.3, 0.2, 0.2 + np.pi / 2])
    assert device.tip_force_capacity(theta, [1e308, 1e308, 0.0]) == device.tip_force_capacity(theta, [1.0, 1.0, 0.0])
    shoulder = np.array([0.0, REPORT.l2, -REPORT.l1])          # in frame s (eqs 4-5)
    along = closed_form.forward_kinematics(theta, REPORT)[:3, 3] - shoulder
    assert device.tip_force_capacity(theta, along) == np.inf
    assert np.isfinite(device.tip_force_capacity(theta, [0.0, 1.0, 0.0]))


def test_huge_input_gives_results_or_errors_without_numpy_warnings(device):
    """A bad-input pass: 1e308 leaked NumPy's "overflow encountered in multiply"."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert device.reachable([1e308] * 3) is False
        with pytest.raises(InvalidInputError, match="^theta: too large"):
            device.encoder_counts([1e308] * 3)


@pytest.mark.parametrize("call, name", [
    (lambda device: Device(3), "phantom"),
    (lambda device: device.available_torque([0.0, 0.3, 0.4], "yes"), "continuous"),
    (lambda device: device.tip_force_capacity([0.0, 0.3, 0.4], [0.0, 0.0, 0.0]), "direction"),
    (lambda device: device.encoder_counts([1e300, 0.0, 0.0]), "theta"),
])
def test_the_device_names_the_bad_argument_in_the_field(device, call, name):
    with pytest.raises(InvalidInputError) as raised:
        call(device)
    assert raised.value.argument == name and str(raised.value) == f"{name}: {raised.value.detail}"
