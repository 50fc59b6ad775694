"""dynamics.build: the models built from a URDF text against Pinocchio's own reading of the
file (buildModelFromUrdf: the same joints, inertias and placements, exactly), the gravity of a
configuration, the SRDF's rotors as armature against rotor inertia x ratio^2, and a model rooted
at another frame against Pinocchio's kinematics of the original (placements premultiplied; the
joint torques, a frame-free quantity, unchanged within 1e-12)."""

import numpy as np
import pinocchio as pin
import pytest

from phantom_pin import config, describe
from phantom_pin.dynamics.build import (
    build_model,
    gravity_of,
    has_rotors,
    load_rotor_parameters,
    rooted_at,
    rooted_at_frame,
)

DESCRIPTION = describe()


def test_the_model_is_pinocchios_reading_of_the_file(tmp_path):
    """build_model of describe()'s URDF text, the tree (mimic=False) and the mimic model, against
    pinocchio.buildModelFromUrdf of the same text written to a file: the same joints, parents,
    placements and inertias, exactly; the configuration's gravity set (the Touch's 9.80665),
    Pinocchio's 9.81 without one."""
    path = tmp_path / "robot.urdf"
    path.write_text(DESCRIPTION.urdf, encoding="utf-8")
    for mimic in (False, True):
        ours = build_model(DESCRIPTION.urdf, DESCRIPTION.config, mimic=mimic)
        theirs = pin.buildModelFromUrdf(str(path), mimic=mimic)
        assert list(ours.names) == list(theirs.names) and (ours.nq, ours.nv) == (theirs.nq, theirs.nv)
        assert list(ours.parents) == list(theirs.parents)
        for a, b in zip(ours.jointPlacements, theirs.jointPlacements):
            assert a.isApprox(b, 0.0)
        for a, b in zip(ours.inertias, theirs.inertias):
            assert np.array_equal(a.toDynamicParameters(), b.toDynamicParameters())
        np.testing.assert_array_equal(ours.gravity.linear, [0, 0, -DESCRIPTION.config.gravity])
    assert build_model(DESCRIPTION.urdf, mimic=False).nq == 7 and build_model(DESCRIPTION.urdf).nq == 3
    touch = describe("touch")
    assert touch.config.gravity == 9.80665 and build_model(touch.urdf).gravity.linear[2] == pytest.approx(-9.81)
    np.testing.assert_array_equal(build_model(touch.urdf, touch.config).gravity.linear, [0, 0, -9.80665])
    np.testing.assert_array_equal(gravity_of(touch.config).vector, [0, 0, -9.80665, 0, 0, 0])


def test_the_rotors_armature_is_rotor_inertia_times_ratio_squared():
    """The Premium 1.5's SRDF rotor_params: armature r^2 J on joints 1-3 (1e-15 relative), 0 on
    the pins; the Touch has no public motor data: no rotors; a URDF of one's own has them."""
    model = build_model(DESCRIPTION.urdf, DESCRIPTION.config)
    load_rotor_parameters(model, DESCRIPTION.srdf)
    rotor, ratios = DESCRIPTION.config.actuation.rotor
    np.testing.assert_allclose(model.armature, rotor * np.array(ratios) ** 2, rtol=1e-15)
    assert rotor > 0 and has_rotors(DESCRIPTION.config) and has_rotors(None)
    assert not has_rotors(config.read("touch"))


def test_a_model_rooted_at_a_frame_is_the_original_seen_from_it():
    """rooted_at(model, X): every frame's world pose is X times the original's (1e-12) at seeded
    angles; gravity rotated alike, so the joint torques of inverse dynamics are the same (1e-12
    N m), also rooted twice (at x, then at y: at y x); rooted_at_frame puts its frame at the
    origin at the neutral configuration."""
    model = build_model(DESCRIPTION.urdf, DESCRIPTION.config)
    x = pin.SE3(pin.rpy.rpyToMatrix(0.3, -0.5, 1.1), np.array([0.1, -0.2, 0.3]))
    y = pin.SE3(pin.rpy.rpyToMatrix(-0.7, 0.2, 0.4), np.array([-0.3, 0.05, 0.2]))
    # rooted twice (the second source's joint placements are no identity): rooted at y x
    rooted = rooted_at(rooted_at(model, x), y)
    x = y * x
    a, b = model.createData(), rooted.createData()
    rng = np.random.default_rng(15)
    for _ in range(5):
        q, v, dv = rng.uniform(-0.5, 0.5, (3, model.nq))
        pin.framesForwardKinematics(model, a, q)
        pin.framesForwardKinematics(rooted, b, q)
        for f in range(1, model.nframes):         # (frame 0, universe: the world itself)
            np.testing.assert_allclose((x * a.oMf[f]).homogeneous, b.oMf[f].homogeneous, rtol=0, atol=1e-12)
        np.testing.assert_allclose(pin.rnea(rooted, b, q, v, dv), pin.rnea(model, a, q, v, dv), rtol=0, atol=1e-12)
    np.testing.assert_allclose(rooted.gravity.linear, x.rotation @ model.gravity.linear, atol=1e-15)
    assert model.gravity.linear[2] == -DESCRIPTION.config.gravity     # the source is not changed
    frame = "report_s"
    at_s = rooted_at_frame(model, frame)
    data = at_s.createData()
    pin.framesForwardKinematics(at_s, data, pin.neutral(at_s))
    assert data.oMf[at_s.getFrameId(frame)].isApprox(pin.SE3.Identity(), 1e-12)
