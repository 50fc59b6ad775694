"""What the hand feels through the servo loop (phantom_pin.interfaces.openhaptics.hand), on the
simulated device at 1 kHz: the mass felt pushing the tip from rest is the apparent mass
Lambda = (J M^-1 J^T)^-1 along the push (computed here from Pinocchio's mass matrix and the
tip Jacobian, the physical law a = Lambda^-1 F at rest), and a share kappa of the inertia
compensated leaves about (1 - kappa) of it; friction compensation cuts the force that drags
the tip at a slow constant speed; a virtual wall's stability changes as the compensation
removes the device's own dissipation."""

import numpy as np
import pytest

from phantom_pin import Device
from phantom_pin.interfaces.openhaptics import Compensator, hand

THETA0 = [0.0, 0.3, 0.4]       # rad, inside every model's stops, far from singular
AXES = np.eye(3)               # OpenHaptics' x, y, z (frame s's axes)


def lambda_along(name, theta, u):
    """1 / (u^T Lambda^-1 u) (kg): the mass felt along u, Lambda^-1 = J M^-1 J^T."""
    device = Device.from_model(name)
    jacobian = device.tip_jacobian(np.array(theta))
    inverse = jacobian @ np.linalg.solve(device.phantom.mass_matrix(np.array(theta)), jacobian.T)
    return 1.0 / (u @ inverse @ u)


@pytest.mark.parametrize("name", ["premium_1_5", "touch"])
def test_the_mass_felt_is_lambda_and_inertia_compensation_halves_it(name):
    """Without inertia compensation the felt mass is Lambda's along each axis within 2 % (the
    arm moves 1 mm or less in the 0.1 s window, friction off in the plant); with kappa = 0.6 it
    is at least 2 times lower, and at most (1 - kappa) Lambda + 15 % (the estimator's lag)."""
    for u in AXES:
        reference = lambda_along(name, THETA0, u)
        felt = hand.apparent_mass(Compensator(name, "joint_torque"), THETA0, u)
        assert abs(felt / reference - 1) < 0.02
        compensated = hand.apparent_mass(Compensator(name, "joint_torque", ("gravity", "inertia"), kappa=0.6),
                                         THETA0, u)
        assert 0 < compensated <= reference / 2
        assert compensated <= 0.4 * reference * 1.15


@pytest.mark.parametrize("name", ["premium_1_5", "touch"])
def test_friction_compensation_cuts_the_backdrive_force_three_times(name):
    """Dragging the tip at 20 mm/s along each axis: the force is at least the Coulomb
    friction's share (positive), and with friction compensated at least 3 times lower."""
    for u in AXES:
        plain = hand.backdrive(Compensator(name, "joint_torque"), THETA0, u)
        compensated = hand.backdrive(Compensator(name, "joint_torque", ("gravity", "friction")), THETA0, u)
        assert plain > 0.02 and abs(compensated) * 3 <= plain


def test_compensating_friction_removes_the_walls_dissipation():
    """A 1000 N/m wall on the Premium 1.5 holds the hand's push still with gravity compensated
    (the device's own friction dissipates), oscillates with friction compensated too (no
    dissipation left: Colgate and Brown's b > K T / 2 + |B| fails), and holds again with a
    virtual damper of 3 N s/m; a 20 000 N/m wall does not hold without compensation."""
    zero, normal = [0.0, 0.0, 0.0], [0.0, 0.0, 1.0]
    assert hand.wall_is_stable(Compensator("premium_1_5", "joint_torque"), zero, normal, 1000.0)
    assert not hand.wall_is_stable(Compensator("premium_1_5", "joint_torque", ("gravity", "friction")), zero, normal,
                                   1000.0)
    assert hand.wall_is_stable(Compensator("premium_1_5", "joint_torque", ("gravity", "friction")), zero, normal,
                               1000.0, damping=3.0)
    assert not hand.wall_is_stable(Compensator("premium_1_5", "joint_torque"), zero, normal, 20000.0)


def test_a_wall_that_is_not_finite_or_negative_is_refused():
    from phantom_pin.exceptions import InvalidInputError
    for stiffness, damping, argument in ((float("inf"), 0.0, "stiffness"), (-1.0, 0.0, "stiffness"),
                                         (100.0, float("nan"), "damping")):
        with pytest.raises(InvalidInputError) as error:
            hand.wall_is_stable(Compensator("touch", "joint_torque"), [0.0] * 3, [0, 0, 1.0], stiffness, damping)
        assert error.value.argument == argument
