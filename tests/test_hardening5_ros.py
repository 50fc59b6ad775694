"""Hardening 5 (issue 42), the ROS and driver conventions: phantom_pin.drivers' HD_CURRENT_TRANSFORM
and gimbal joint states, and the ROS node's computation (phantom_pin.ros2.Bridge), each against
something written out here from the drivers' published formulas, OpenHaptics' guide or the
report's closed form."""

from __future__ import annotations

import math

import numpy as np
import pytest

from phantom_pin import drivers
from phantom_pin.exceptions import InvalidInputError


def rodrigues(axis: np.ndarray, angle: float) -> np.ndarray:
    """The rotation by ``angle`` (rad) about the unit ``axis``: I + sin K + (1 - cos) K^2."""
    x, y, z = axis / np.linalg.norm(axis)
    k = np.array([[0, -z, y], [z, 0, -x], [-y, x, 0]])
    return np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * k @ k


def transform(rotation: np.ndarray, translation_mm) -> np.ndarray:
    """A 4x4 homogeneous transform (translation in mm)."""
    out = np.eye(4)
    out[:3, :3], out[:3, 3] = rotation, translation_mm
    return out


ROTATION = rodrigues(np.array([0.3, -0.5, 0.8]), 0.9)


# -- M3 and the mutations of drivers.py ------------------------------------------------------------

@pytest.mark.parametrize("pose", [
    "abc",                                                          # was a bare ValueError
    transform(1.1 * ROTATION, [10, 20, 30]) * [[1], [1], [1], [1]],  # scaled: was accepted
    transform(ROTATION, [1e308, 0, 0]) / 1000,                      # 1e305 m: inf mm came back
    transform(ROTATION @ np.diag([-1.0, 1, 1]), [0, 0, 0]),         # a mirror (det -1)
    [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0]],                     # 3x4
])
def test_openhaptics_transform_from_pose_refuses_what_is_not_a_finite_rigid_pose(pose):
    """M3: each refused with InvalidInputError naming ``pose``."""
    with pytest.raises(InvalidInputError) as error:
        drivers.openhaptics_transform_from_pose(pose)
    assert error.value.argument == "pose"


def test_a_mirrored_hd_current_transform_is_refused():
    """Mutation (drivers): a mirrored HD_CURRENT_TRANSFORM (an orthogonal rotation part of
    determinant -1, which R R^T = I alone lets through) was accepted."""
    for mirror in (np.diag([-1.0, 1, 1]), -np.eye(3)):
        rotation = ROTATION @ mirror
        assert np.allclose(rotation @ rotation.T, np.eye(3), atol=1e-12) and np.linalg.det(rotation) < 0
        flat = transform(rotation, [12.0, -70.0, -50.0]).T.ravel()   # column-major
        with pytest.raises(InvalidInputError) as error:
            drivers.pose_from_openhaptics_transform(flat)
        assert error.value.argument == "transform"


def test_a_row_major_hd_current_transform_is_refused():
    """Mutation (drivers): the last-row check removed, a row-major transform (its translation
    read as the last row, its rotation transposed, still proper) was accepted. Column-major,
    OpenHaptics' order (the translation at 12..14), the same numbers give the pose in m."""
    matrix = transform(ROTATION, [12.0, -70.0, -50.0])
    with pytest.raises(InvalidInputError) as error:
        drivers.pose_from_openhaptics_transform(matrix.ravel())        # row-major
    assert error.value.argument == "transform"
    flat = matrix.T.ravel()
    assert np.array_equal(flat[12:15], [12.0, -70.0, -50.0])
    assert np.abs(drivers.pose_from_openhaptics_transform(flat)[:3, :3] - ROTATION).max() < 1e-15


def test_omni_firewire_gimbal_rates_convert_without_the_offsets():
    """Mutation (drivers): omni_firewire's gimbal rates read back with the angle offsets
    subtracted. fsuarez6/phantom_omni omni_state.cpp 188-193 publishes yaw = pi - g1, pitch =
    -g2 - 3 pi / 4, roll = -g3 - pi, written out here: the rates of a motion g(t) are the finite
    difference of those positions (the map is affine: exact up to rounding, 1e-6 rad/s)."""
    rng = np.random.default_rng(42)
    g0, rate, h = rng.uniform(-0.5, 0.5, 3), rng.uniform(-2, 2, 3), 1e-3

    def published(g):
        return np.array([math.pi - g[0], -g[1] - 3 * math.pi / 4, -g[2] - math.pi])

    published_rate = (published(g0 + rate * h) - published(g0)) / h
    names = ["roll", "yaw", "pitch"]
    order = [2, 0, 1]
    back = drivers.gimbal_from_joint_state(names, published_rate[order], convention="omni_firewire", rates=True)
    assert np.abs(back - rate).max() < 1e-6
    positions = drivers.gimbal_from_joint_state(names, published(g0)[order], convention="omni_firewire")
    assert np.abs(positions - g0).max() < 1e-14


def test_gimbal_joint_states_with_a_prefix_read_their_own_names():
    """Mutation (drivers): gimbal joint states with a prefix were never tested. Two devices in
    one message (unprefixed and left_): each prefix reads its own three values (raw convention:
    the values themselves), and the names written carry it."""
    names = ["left_roll", "yaw", "left_yaw", "pitch", "left_pitch", "roll"]
    values = [0.3, -1.0, 0.1, -2.0, 0.2, -3.0]
    assert np.array_equal(drivers.gimbal_from_joint_state(names, values, prefix="left_"), [0.1, 0.2, 0.3])
    assert np.array_equal(drivers.gimbal_from_joint_state(names, values), [-1.0, -2.0, -3.0])
    written, position = drivers.joint_state_from_gimbal([0.1, 0.2, 0.3], prefix="left_")
    assert written == ["left_yaw", "left_pitch", "left_roll"] and np.array_equal(position, [0.1, 0.2, 0.3])
    with pytest.raises(InvalidInputError) as error:
        drivers.gimbal_from_joint_state(["yaw", "pitch", "roll"], [0, 0, 0], prefix="left_")
    assert error.value.argument == "names"
