"""phantom_pin.device.feel, each measure against an independent reference: the apparent mass
against the tip's acceleration under a known force at rest (the report's closed-form M and the
central differences of eq. 10 for the Premium 1.5; Pinocchio's forward dynamics for the others),
the backdrive force against virtual work with rates from finite differences, the force capacity
against the closed form's gravity and the limits, the workspace volume against a quasi-Monte-Carlo
count of the points the closed-form inverse kinematics reaches."""

import math

import numpy as np
import pytest
from scipy.stats import qmc

from phantom_pin import Device, InvalidInputError, closed_form, feel
from phantom_pin.config.sampling import sample_postures
from phantom_pin.device.feel import AXES, workspace_box, workspace_volume

H = 1e-6                                  # rad, the central differences' step
MODELS = ("premium_1_5", "premium_1_5_cad", "touch")


@pytest.fixture(scope="module")
def devices():
    return {name: Device.from_model(name) for name in MODELS}


def _postures(device, n, seed):
    """n seeded postures inside the stops, 0.05 rad from every limit, the nominal one first."""
    theta = sample_postures(device.config.limits, n - 1, np.random.default_rng(seed), margin=0.05)
    return np.vstack([np.zeros(3), theta])


def _jacobian_fd(position, theta):
    """d(tip)/d(theta) (3, 3) by central differences of ``position`` (theta -> (3,) m)."""
    return np.column_stack([(position(theta + H * e) - position(theta - H * e)) / (2 * H) for e in np.eye(3)])


def _acceleration_reference(device, theta):
    """(3, 3): column k the tip's acceleration (m/s^2) under a unit tip force along axis k, at rest
    with gravity held, i.e. Lambda^-1; the report's closed form for the Premium 1.5, else the
    plant's forward dynamics (crba and nonLinearEffects) on a finite-difference Jacobian."""
    phantom = device.phantom
    if device.config.name == "premium_1_5":
        report = device.config.report
        jacobian = _jacobian_fd(lambda q: closed_form.forward_kinematics(q, report)[:3, 3], theta)
        ddtheta = np.linalg.solve(closed_form.mass_matrix(theta, report), jacobian.T)
    else:
        jacobian = _jacobian_fd(lambda q: phantom.forward_kinematics(q)[:3, 3], theta)
        ddtheta = np.column_stack([phantom.forward_dynamics(theta, np.zeros(3), phantom.gravity(theta) + jacobian.T @ f)
                                   for f in np.eye(3)])
    return jacobian @ ddtheta          # at rest dJ/dt dtheta = 0: the tip's acceleration is J ddtheta


@pytest.mark.parametrize("name", MODELS)
def test_the_apparent_mass_is_the_tips_response_to_a_force_at_rest(devices, name):
    """Lambda^-1 F is the tip's acceleration under F (to 1e-7 relative: the central differences'
    rounding, eps / H); the principal masses are the eigenvalues of that response's inverse and
    each axis mass is f / (the acceleration's component along the force)."""
    device = devices[name]
    for theta in _postures(device, 4, seed=52):
        measures = feel(device, theta)
        response = _acceleration_reference(device, theta)
        np.testing.assert_allclose(np.linalg.inv(measures.apparent_mass), response, rtol=0,
                                   atol=1e-7 * np.abs(response).max())
        np.testing.assert_allclose(measures.principal_masses, 1e3 * np.linalg.eigvalsh(np.linalg.inv(response)),
                                   rtol=1e-7)
        np.testing.assert_allclose(measures.axis_masses, 1e3 / np.diag(response), rtol=1e-7)
        lam = measures.apparent_mass
        for mass, direction in zip(measures.principal_masses, measures.directions.T):
            np.testing.assert_allclose(lam @ direction, mass / 1e3 * direction, atol=1e-14)


def test_the_nominal_premiums_apparent_mass_is_the_report_inertia_over_the_levers(devices):
    """At theta = 0 the Premium 1.5's M is diagonal and J = diag(l1, l1, l2) (eq. 10): the
    axis masses are M11 / l1^2, M22 / l1^2, M33 / l2^2 of the closed form."""
    device = devices["premium_1_5"]
    report = device.config.report
    measures = feel(device)
    assert measures.posture == "zero" and np.array_equal(measures.theta, np.zeros(3))
    m = np.diag(closed_form.mass_matrix(np.zeros(3), report))
    levers = np.array([report.l1, report.l1, report.l2])
    np.testing.assert_allclose(measures.axis_masses, 1e3 * m / levers**2, rtol=1e-12)


@pytest.mark.parametrize("name", ["premium_1_5", "touch"])
def test_the_backdrive_force_does_the_friction_laws_virtual_work(devices, name):
    """J^T F = tau_f for every virtual displacement (J here by central differences of eq. 10),
    so F . v = tau_f . dtheta: the hand's power is the friction's, to 1e-7 relative; rates from
    the closed form's Jacobian, never Device.tip_jacobian."""
    device = devices[name]
    report, law = device.config.report, device.config.actuation.friction
    speed = 0.2
    for theta in _postures(device, 4, seed=7)[1:]:        # generic postures: every joint moves
        measures = feel(device, theta, speed=speed)
        jacobian = _jacobian_fd(lambda q: closed_form.forward_kinematics(q, report)[:3, 3], theta)
        for k in range(3):
            rates = np.linalg.solve(jacobian, speed * np.eye(3)[k])
            rates[np.abs(rates) < 1e-9 * np.abs(rates).max()] = 0.0    # a joint the motion leaves still (theta1 for y)
            coulomb = np.asarray(law.coulomb) * np.sign(rates)
            sliding = coulomb + np.asarray(law.viscous) * rates
            np.testing.assert_allclose(jacobian.T @ measures.breakaway[k], coulomb, rtol=1e-7, atol=1e-10)
            np.testing.assert_allclose(jacobian.T @ measures.sliding[k], sliding, rtol=1e-7, atol=1e-10)
            assert measures.sliding_along[k] * speed == pytest.approx(sliding @ rates, rel=1e-7)
            assert measures.breakaway_along[k] * speed == pytest.approx(coulomb @ rates, rel=1e-7)


def test_at_the_nominal_posture_one_joint_moves_per_axis(devices):
    """At theta = 0 moving along x turns joint 1 alone, along y joint 2, along z joint 3 (J is
    diagonal): the breakaway force is that joint's Coulomb torque over its lever, the others add
    nothing (a joint left still by rounding does not break away)."""
    device = devices["premium_1_5"]
    p, coulomb = device.config.report, device.config.actuation.friction.coulomb
    measures = feel(device)
    np.testing.assert_allclose(measures.breakaway, np.diag(np.array(coulomb) / [p.l1, p.l1, p.l2]), atol=1e-15)


@pytest.mark.parametrize("name", ["premium_1_5", "touch"])
def test_the_force_capacity_puts_a_joint_at_its_limit(devices, name):
    """Along each axis the peak and continuous forces, with gravity (the closed form's), need
    torques within the limits, one joint exactly at its limit (to 1e-12 relative)."""
    device = devices[name]
    report, actuation = device.config.report, device.config.actuation
    theta = _postures(device, 2, seed=3)[1]
    measures = feel(device, theta)
    jacobian = _jacobian_fd(lambda q: closed_form.forward_kinematics(q, report)[:3, 3], theta)
    gravity = closed_form.gravity(theta, report)
    if name == "touch":
        gravity = device.phantom.gravity(theta)       # the Touch's locked gimbal is not in the report's model
    for forces, limit in ((measures.peak_force, actuation.peak), (measures.continuous_force, actuation.effort)):
        for force, axis in zip(forces, AXES):
            share = np.abs(gravity + jacobian.T @ (force * axis)) / np.asarray(limit)
            assert share.max() == pytest.approx(1.0, rel=1e-7)
    if name == "touch":              # no public motor data: one limit for both
        np.testing.assert_array_equal(measures.peak_force, measures.continuous_force)
    else:
        assert (measures.peak_force > 4 * measures.continuous_force).all()


@pytest.mark.parametrize("name", ["premium_1_5", "touch"])
def test_the_workspace_volume_is_the_reachable_volume(devices, name):
    """The integral of |det J| over the stops equals the volume of the points the closed-form
    inverse kinematics reaches inside the stops (Device.reachable), counted on 2^14 scrambled
    Sobol points of the box: within 1 % (the count's error measured over four scramblings:
    0.4 % at most); the quadrature has converged (48 against 64 nodes: 1e-5 relative)."""
    device = devices[name]
    lower, upper = workspace_box(device)
    points = lower + (upper - lower) * qmc.Sobol(3, seed=11).random_base2(14)
    counted = np.prod(upper - lower) * device.reachable(points).mean()
    volume = workspace_volume(device)
    assert volume == pytest.approx(counted, rel=0.01)
    assert volume == pytest.approx(workspace_volume(device, 64), rel=1e-5)


@pytest.mark.parametrize("name", ["premium_1_5", "touch"])
def test_the_workspace_box_bounds_every_posture_and_is_reached(devices, name):
    """Every tip of 20000 seeded postures inside the stops lies in the box (to 1e-12 m), and the
    box's faces are attained: the refined extreme is no worse than the best of those samples
    and within 1 cm of it (the samples approach it, the optimiser reaches it)."""
    device = devices[name]
    lower, upper = workspace_box(device)
    theta = sample_postures(device.config.limits, 20000, np.random.default_rng(5))
    tips = closed_form.forward_kinematics(theta, device.config.report)[:, :3, 3]
    assert (tips >= lower - 1e-12).all() and (tips <= upper + 1e-12).all()
    assert (tips.min(axis=0) - lower < 0.01).all() and (upper - tips.max(axis=0) < 0.01).all()


def test_a_posture_outside_the_stops_a_singular_one_and_a_bad_speed_are_refused(devices):
    device = devices["touch"]
    with pytest.raises(InvalidInputError) as error:
        feel(device, [0.0, -0.2, 0.0])
    assert error.value.argument == "theta" and "outside the stops" in str(error.value)
    # the tip on axis 1 (l1 cos(theta2) + l2 sin(theta3) = 0 with l1 = l2), inside the Touch's stops
    singular = np.array([0.0, 1.74, 1.5 * math.pi - 1.74])
    assert device.within_limits(singular)
    with pytest.raises(InvalidInputError) as error:
        feel(device, singular)
    assert error.value.argument == "theta" and "singular" in str(error.value)
    for speed in (0.0, -0.1, math.nan, math.inf, True, "0.1"):
        with pytest.raises(InvalidInputError) as error:
            feel(device, speed=speed)
        assert error.value.argument == "speed"
    with pytest.raises(InvalidInputError) as error:
        feel("touch")
    assert error.value.argument == "device"
