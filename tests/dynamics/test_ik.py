"""Phantom.inverse_kinematics (dynamics/ik.py: damped Newton from seeds) against the report's
closed form (eq. 11): round trips, every point of the shell on both branches, behind the shoulder."""

import numpy as np
import pytest

from helpers import REPORT
from phantom_pin import UnreachableTargetError
from phantom_pin import closed_form as cf


def test_inverse_kinematics_round_trips(phantom, states):
    """Where the tip is in front of axis 1 (eq. 11's theta1 is the posture's), IK gives the
    posture back; behind it (theta2 near its upper stop), another posture with the same tip."""
    p = phantom.config.report
    theta = states[0]
    front = p.l1 * np.cos(theta[:, 1]) + p.l2 * np.sin(theta[:, 2]) > 0
    assert 0 < (~front).sum() < len(theta) / 4
    position = cf.forward_kinematics(theta, REPORT)[:, :3, 3]
    np.testing.assert_allclose(phantom.inverse_kinematics(position[front]), theta[front], atol=1e-9)
    behind = phantom.inverse_kinematics(position[~front])
    np.testing.assert_allclose(cf.forward_kinematics(behind, REPORT)[:, :3, 3], position[~front], atol=1e-12)
    other = phantom.inverse_kinematics(position[:100], branch="other")
    np.testing.assert_allclose(cf.forward_kinematics(other, REPORT)[:, :3, 3], position[:100], atol=1e-12)
    with pytest.raises(UnreachableTargetError, match="position"):
        phantom.inverse_kinematics([0.0, 0.17, 0.5])


def test_inverse_kinematics_agrees_with_the_closed_form_everywhere_on_the_shell(phantom):
    """Seeded targets on the inner (|l1 - l2|) and outer (l1 + l2) shell boundaries and
    inside, all round the shoulder (behind it too), both branches: Phantom's Newton and
    the closed form give the same angles, compared modulo 2 pi. Inside to 1e-9 rad; on a
    boundary the map is folded and both sides are good only to about sqrt(eps) (measured
    2.4e-6 rad), so 1e-5 rad there, with the tips within 1e-12 m."""
    p = phantom.config.report
    shoulder = np.array([0.0, p.l2, -p.l1])
    rng = np.random.default_rng(11)
    direction = np.vstack([rng.normal(size=(60, 3)), np.eye(3), -np.eye(3)])
    direction /= np.linalg.norm(direction, axis=1, keepdims=True)
    for radius, tolerance in ((abs(p.l1 - p.l2), 1e-5), (p.l1 + p.l2, 1e-5), (0.25, 1e-9)):
        target = shoulder + radius * direction
        for branch in ("report", "other"):
            ours, reference = phantom.inverse_kinematics(target, branch), cf.inverse_kinematics(target, REPORT, branch)
            assert np.abs(np.angle(np.exp(1j * (ours - reference)))).max() < tolerance, (radius, branch)
            np.testing.assert_allclose(cf.forward_kinematics(ours, REPORT)[:, :3, 3], target, atol=1e-12)


def test_inverse_kinematics_behind_the_shoulder_gives_plus_pi_like_the_closed_form(phantom):
    """Straight behind axis 1 (x = 0, z < -l1), theta1 is pi in both (Newton's to 1e-12
    rad), not -pi."""
    target = cf.forward_kinematics([np.pi, 0.2, 0.3], REPORT)[:3, 3]
    target[0] = 0.0
    for theta in (phantom.inverse_kinematics(target), cf.inverse_kinematics(target, REPORT)):
        assert abs(theta[0] - np.pi) < 1e-12
        np.testing.assert_allclose(theta[1:], [0.2, 0.3], atol=1e-9)
