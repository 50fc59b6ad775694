"""description.mjcf: each model's MJCF as describe() generates it, loaded in MuJoCo, against its
URDF read by yourdfpy and its configuration: every body's mass and principal inertias (1e-12
relative: full precision written, MuJoCo's eigen-decomposition), the arm joints' ranges (the
device's stops; none on a mimic joint), damping and friction loss (exact), the armature of the
rotors (rotor inertia x ratio^2) and the motors' gears, the mimic tags as joint equalities
(offset, multiplier) and the gravity."""

import mujoco
import numpy as np
import pytest
import yourdfpy

from phantom_pin import describe


@pytest.fixture(scope="module", params=["premium_1_5", "premium_1_5_cad", "touch"])
def case(request, tmp_path_factory):
    """describe()'s URDF read by yourdfpy and its MJCF generated now (mjcf_texts) in MuJoCo."""
    description = describe(request.param)
    path = tmp_path_factory.mktemp(request.param) / "robot.urdf"
    path.write_text(description.urdf, encoding="utf-8")
    robot = yourdfpy.URDF.load(str(path), build_scene_graph=False, load_meshes=False).robot
    return description.config, robot, mujoco.MjModel.from_xml_string(description.mjcf)


def test_the_bodies_mass_and_inertia_are_the_urdfs(case):
    _, robot, model = case
    inertial = {link.name: link.inertial for link in robot.links if link.inertial is not None}
    assert inertial
    for name, urdf in inertial.items():
        body = model.body(name)
        assert body.mass[0] == pytest.approx(urdf.mass, rel=1e-15), name
        rotation = urdf.origin[:3, :3]
        principal = np.linalg.eigvalsh(rotation @ urdf.inertia @ rotation.T)
        np.testing.assert_allclose(np.sort(body.inertia), principal, rtol=1e-12, atol=1e-18, err_msg=name)
    total = sum(urdf.mass for urdf in inertial.values())
    assert model.body_mass.sum() == pytest.approx(total, rel=1e-14)


def test_the_joints_are_the_urdfs_with_the_rotors_armature(case):
    cfg, robot, model = case
    for joint in robot.joints:
        if joint.type != "revolute":
            continue
        mj = model.joint(joint.name)
        if joint.name in ("joint1", "joint2", "joint3"):      # the device's stops, not the URDF's box
            j = int(joint.name[-1]) - 1
            np.testing.assert_array_equal(mj.range, [cfg.limits.stops.lower[j], cfg.limits.stops.upper[j]])
        elif joint.mimic is not None:                       # bounded through its primary's equality
            assert not model.jnt_limited[mj.id], joint.name
        if joint.dynamics is not None:
            assert model.dof_damping[mj.dofadr[0]] == float(joint.dynamics.damping or 0.0), joint.name
            assert model.dof_frictionloss[mj.dofadr[0]] == float(joint.dynamics.friction or 0.0), joint.name
    rotor, ratios = cfg.actuation.rotor
    for k, name in enumerate(("joint1", "joint2", "joint3")):
        armature = model.dof_armature[model.joint(name).dofadr[0]]
        assert armature == pytest.approx(rotor * ratios[k] ** 2, rel=1e-14, abs=1e-300), name
        gear = model.actuator(_actuators(model)[k]).gear[0]
        assert gear == pytest.approx(cfg.actuation.ratios[k] if cfg.actuation.motor is not None else 1.0, rel=1e-15)


def _actuators(model):
    return [model.actuator(i).name for i in range(model.nu)]


def test_the_mimic_tags_are_joint_equalities_and_gravity_is_the_configurations(case):
    cfg, robot, model = case
    mimics = {j.name: j.mimic for j in robot.joints if j.mimic is not None}
    equalities = {}
    for i in range(model.neq):
        if model.eq_type[i] == mujoco.mjtEq.mjEQ_JOINT and model.eq_obj2id[i] >= 0:
            follower = model.joint(model.eq_obj1id[i]).name
            equalities[follower] = (model.joint(model.eq_obj2id[i]).name, *model.eq_data[i, :2])
    assert equalities == {name: (m.joint, m.offset, m.multiplier) for name, m in mimics.items()}
    np.testing.assert_allclose(model.opt.gravity, [0, 0, -cfg.gravity], rtol=1e-15)
