"""closed_form against the appendix's numbers and the identities the report states."""

import dataclasses

import numpy as np
import pytest

from helpers import REPORT
from phantom_pin import InvalidInputError, UnreachableTargetError
from phantom_pin import closed_form as cf
from phantom_pin.report import appendix


def _hat(v):
    return np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])


def test_torques_equal_the_appendix_to_its_printed_precision(states):
    params = dataclasses.replace(REPORT, Iayy=appendix.APPENDIX_IAYY)
    printed, bound = appendix.torques(*states)
    assert np.all(np.abs(cf.inverse_dynamics(*states, params) - printed) <= bound)


def test_mass_matrix_is_the_appendix_coefficient_of_ddtheta(states):
    """Column j of M is tau(theta, 0, e_j) - tau(theta, 0, 0) of the appendix's printed
    torques (Iayy as the appendix), within the printed rounding of both."""
    params = dataclasses.replace(REPORT, Iayy=appendix.APPENDIX_IAYY)
    theta = states[0]
    zero = np.zeros_like(theta)
    base, base_bound = appendix.torques(theta, zero, zero)
    m = cf.mass_matrix(theta, params)
    for j, e in enumerate(np.eye(3)):
        column, bound = appendix.torques(theta, zero, zero + e)
        assert np.all(np.abs(m[:, :, j] - (column - base)) <= bound + base_bound), j


def test_mass_matrix_is_positive_definite(states):
    assert np.linalg.eigvalsh(cf.mass_matrix(states[0], REPORT)).min() > 0


def test_mdot_minus_2c_is_skew_symmetric(states):
    theta, dtheta, _ = states
    h = 1e-6  # central difference of M along dtheta: error O(h^2) ~ 1e-15
    mdot = (cf.mass_matrix(theta + h * dtheta, REPORT) - cf.mass_matrix(theta - h * dtheta, REPORT)) / (2 * h)
    n = mdot - 2 * cf.coriolis_matrix(theta, dtheta, REPORT)
    assert np.abs(n + np.swapaxes(n, -1, -2)).max() < 1e-9 * np.abs(mdot).max()


def test_gravity_is_the_gradient_of_the_potential(states):
    theta = states[0]
    h = 1e-6
    gradient = np.stack([(cf.potential_energy(theta + h * e, REPORT)
                          - cf.potential_energy(theta - h * e, REPORT)) / (2 * h)
                         for e in np.eye(3)], axis=-1)
    np.testing.assert_allclose(cf.gravity(theta, REPORT), gradient, atol=1e-10)


def test_jacobians_follow_their_definitions_eqs_21_and_23(states):
    """J^s = [(dg/dtheta_i g^-1)^vee] and J^b = [(g^-1 dg/dtheta_i)^vee], by finite differences."""
    theta = states[0][:200]
    h = 1e-6
    g = cf.forward_kinematics(theta, REPORT)
    g_inv = np.linalg.inv(g)
    for i, e in enumerate(np.eye(3)):
        dg = (cf.forward_kinematics(theta + h * e, REPORT) - cf.forward_kinematics(theta - h * e, REPORT)) / (2 * h)
        for twist, jacobian in ((dg @ g_inv, cf.spatial_jacobian(theta, REPORT)),
                                (g_inv @ dg, cf.body_jacobian(theta, REPORT))):
            vee = np.concatenate([twist[:, :3, 3], np.stack([twist[:, 2, 1], twist[:, 0, 2], twist[:, 1, 0]], -1)], -1)
            np.testing.assert_allclose(jacobian[:, :, i], vee, atol=1e-9)


def test_spatial_jacobian_is_the_adjoint_of_the_body_jacobian(states):
    theta = states[0]
    g = cf.forward_kinematics(theta, REPORT)
    for gi, js, jb in zip(g, cf.spatial_jacobian(theta, REPORT), cf.body_jacobian(theta, REPORT)):
        r, p = gi[:3, :3], gi[:3, 3]
        adjoint = np.block([[r, _hat(p) @ r], [np.zeros((3, 3)), r]])
        np.testing.assert_allclose(js, adjoint @ jb, atol=1e-12)


def test_inverse_kinematics_inverts_forward_kinematics(states, limits):
    """Eq. 11 takes theta1 towards the tip: where the tip is in front of axis 1 the posture
    comes back; behind it (theta2 near its upper stop), another posture with the same tip."""
    p = REPORT
    theta = states[0]
    front = p.l1 * np.cos(theta[:, 1]) + p.l2 * np.sin(theta[:, 2]) > 0
    position = cf.forward_kinematics(theta, REPORT)[:, :3, 3]
    np.testing.assert_allclose(cf.inverse_kinematics(position[front], REPORT), theta[front], atol=1e-9)
    np.testing.assert_allclose(cf.forward_kinematics(cf.inverse_kinematics(position, REPORT), REPORT)[:, :3, 3],
                               position, atol=1e-12)
    other = cf.inverse_kinematics(position, REPORT, branch="other")
    np.testing.assert_allclose(cf.forward_kinematics(other, REPORT)[:, :3, 3], position, atol=1e-12)
    assert np.all(np.cos(other[:, 2] - other[:, 1]) < 0)  # the mirrored elbow


def test_forward_kinematics_of_workspace_points_round_trips():
    """FK(IK(p)) = p on a seeded cloud of points of the reachable shell."""
    p = REPORT
    rng = np.random.default_rng(7)
    direction = rng.normal(size=(1000, 3))
    direction /= np.linalg.norm(direction, axis=1, keepdims=True)
    radius = rng.uniform(abs(p.l1 - p.l2) * 1.01, (p.l1 + p.l2) * 0.99, (1000, 1))
    target = np.array([0, p.l2, -p.l1]) + radius * direction
    for branch in ("report", "other"):
        solution = cf.inverse_kinematics(target, REPORT, branch)
        np.testing.assert_allclose(cf.forward_kinematics(solution, REPORT)[:, :3, 3],
                                   target, atol=1e-12)


@pytest.mark.parametrize("target", [[0, 0.17, 0.2], [0.0, 0.17, -0.215]])
def test_unreachable_targets_raise(target):
    with pytest.raises(UnreachableTargetError, match="position"):
        cf.inverse_kinematics(target, REPORT)


@pytest.mark.parametrize("bad, message", [([0, 0], "shape"), ([0, np.nan, 0], "NaN"),
                                          ([[0, 0, np.inf]], "NaN or inf"), ("abc", "numbers"),
                                          (np.zeros((0, 3)), "at least one state")])
def test_bad_input_names_the_argument(bad, message):
    with pytest.raises(InvalidInputError, match=f"theta: .*{message}"):
        cf.mass_matrix(bad, REPORT)


def test_batch_shapes_and_mismatch():
    theta = np.zeros((4, 5, 3))
    assert cf.forward_kinematics(theta, REPORT).shape == (4, 5, 4, 4)
    assert cf.inverse_dynamics(theta, theta, theta, REPORT).shape == (4, 5, 3)
    with pytest.raises(InvalidInputError, match="same shape"):
        cf.coriolis_matrix(np.zeros((2, 3)), np.zeros((3, 3)), REPORT)
