"""The Touch's stylus gimbal (config/touch/gimbal.yaml): its mass properties against the SymPy
integrals of its stated solids, the stylus's pose against Ubitrack's formula of OpenHaptics'
raw angles, in Pinocchio, yourdfpy and MuJoCo, its Jacobian against complex-step derivatives,
and its load in the arm's gravity and mass matrix against the closed form plus the rigid-body
laws of the three gimbal links, written here from Ubitrack's kinematics."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from helpers import CONFIG_DIR
from phantom_pin import InvalidInputError, ParameterFileError, Phantom, config
from phantom_pin.interfaces import conventions
from phantom_pin.report import closed_form
from references import touch as touch_reference
from references.gimbal import H, gimbal_gravity, gimbal_mass_matrix, openhaptics, step, ubitrack

TOUCH = CONFIG_DIR.parent / "touch"
GIMBAL_YAML = yaml.safe_load((TOUCH / "gimbal.yaml").read_text())
LIMITS = yaml.safe_load((TOUCH / "joint_limits.yaml").read_text())
JOINTS = ("joint4", "joint5", "joint6")


@pytest.fixture(scope="module")
def touch() -> Phantom:
    return Phantom.from_model("touch")


def states(n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """``n`` seeded (theta, gimbal) (rad), theta inside the stops (coupled ones too), the
    gimbal inside its ranges (both from the YAML)."""
    rng = np.random.default_rng(seed)
    stops = LIMITS["stops"]
    lower = [stops[j]["lower"] for j in ("joint1", "joint2", "joint3")]
    upper = [stops[j]["upper"] for j in ("joint1", "joint2", "joint3")]
    pool = rng.uniform(lower, upper, (8 * n, 3))
    keep = ((pool[:, 1] - pool[:, 2] <= stops["theta2_minus_theta3_max"])
            & (pool[:, 2] - pool[:, 1] <= stops["theta3_minus_theta2_max"]))
    theta = pool[keep][:n]
    ranges = GIMBAL_YAML["joints"]
    gimbal = rng.uniform([ranges[j]["lower"] for j in JOINTS], [ranges[j]["upper"] for j in JOINTS], (n, 3))
    return theta, gimbal


# -- the description ---------------------------------------------------------------------------

def test_the_gimbal_links_are_the_integrals_of_their_stated_solids():
    """config's gimbal links (URDF link axes: x = the report's z, y = x, z = y) equal the SymPy
    integrals of gimbal.yaml's solids, to 1e-12 relative."""
    links = config.read("touch").gimbal.links
    axes = {"xx": "zz", "yy": "xx", "zz": "yy"}  # link axis -> report axis
    for name, reference in touch_reference.GIMBAL_REFERENCE.items():
        link, mass = links[name], reference["mass"]
        assert link.mass == pytest.approx(mass, rel=1e-12)
        com = np.array(reference["first"]) / mass  # report axes
        assert np.allclose(link.com, [com[2], com[0], com[1]], rtol=0, atol=1e-15)
        about_com = {k: reference["second"][k] - mass * (com @ com - com[i] ** 2)
                     for i, k in enumerate(("xx", "yy", "zz"))}
        xx, xy, xz, yy, yz, zz = link.inertia
        assert (xy, xz, yz) == (0, 0, 0)
        for key, value in zip(("xx", "yy", "zz"), (xx, yy, zz)):
            assert value == pytest.approx(about_com[axes[key]], rel=1e-12)


def test_the_models_without_a_public_gimbal_have_none(touch):
    for name in ("premium_1_5", "premium_1_5_cad"):
        phantom = Phantom.from_model(name)
        assert phantom.config.gimbal is None and phantom.gimbal_joints == () and phantom.stylus_model is None
        with pytest.raises(InvalidInputError, match="no stylus gimbal") as error:
            phantom.stylus_pose(np.zeros(3), np.zeros(3))
        assert error.value.argument == "gimbal"
        with pytest.raises(InvalidInputError, match="gimbal"):
            phantom.gravity(np.zeros(3), np.zeros(3))
    assert touch.gimbal_joints == JOINTS and touch.model.nq == 3 and touch.stylus_model.nq == 6


# -- the stylus's pose ---------------------------------------------------------------------------

def test_the_stylus_pose_is_ubitracks_formula_of_the_raw_openhaptics_angles(touch):
    """Rotation and gimbal centre (Ubitrack) and the tip 39 mm along the stylus's -z
    (sawSensablePhantom), 1e-12, over 200 states inside the stops and the gimbal's ranges."""
    theta, gimbal = states(200, seed=3)
    poses, tips = touch.stylus_pose(theta, gimbal), touch.stylus_tip_pose(theta, gimbal)
    assert poses.shape == tips.shape == (200, 4, 4)
    for t, g, pose, tip in zip(theta, gimbal, poses, tips):
        position, rotation = ubitrack(openhaptics(t, g))
        assert np.abs(pose[:3, :3] - rotation).max() < 1e-12
        assert np.abs(pose[:3, 3] - position).max() < 1e-12
        assert np.abs(tip[:3, :3] - rotation).max() < 1e-12
        assert np.abs(tip[:3, 3] - (position - GIMBAL_YAML["tip_offset"] * rotation[:, 2])).max() < 1e-12
    one = touch.stylus_pose(theta[0], gimbal[0])
    assert np.array_equal(one, poses[0])


def test_the_stylus_jacobian_is_the_complex_step_derivative_of_ubitracks_pose(touch):
    """Columns (v, omega) in frame s per rate of (theta, g): v = d position / dq, [omega]x =
    dR/dq R^T, by complex steps of Ubitrack's formula (exact to rounding): 1e-12."""
    theta, gimbal = states(20, seed=4)
    for t, g in zip(theta, gimbal):
        jacobian = touch.stylus_jacobian(t, g)
        q, expected = np.concatenate([t, g]), np.zeros((6, 6))
        position, rotation = ubitrack(openhaptics(t, g))
        for k in range(6):
            shifted = step(q, k, H * 1j)
            p, r = ubitrack(openhaptics(shifted[:3], shifted[3:]))
            dp, dr = p.imag / H, r.imag / H
            omega = dr @ rotation.T
            expected[3:, k] = omega[2, 1], omega[0, 2], omega[1, 0]
            # a spatial twist's v is the velocity of the point at frame s's origin
            expected[:3, k] = dp - np.cross(expected[3:, k], position)
        assert np.abs(jacobian - expected).max() < 1e-12


def test_yourdfpy_and_mujoco_read_the_same_stylus_pose(touch):
    """The committed URDF in yourdfpy (its mimic joints) and the committed MJCF in MuJoCo (the
    gimbal's equalities off, the joints set): stylus and stylus_tip in report_s, 1e-12."""
    import mujoco
    import yourdfpy

    model = config.MODELS["touch"]
    urdf = yourdfpy.URDF.load(str(model.urdf), build_scene_graph=True, load_meshes=False)
    mj = mujoco.MjModel.from_xml_path(str(model.mjcf))
    data = mujoco.MjData(mj)
    theta, gimbal = states(30, seed=5)
    coupling = touch.coupling
    for t, g in zip(theta, gimbal):
        urdf.update_cfg({**dict(zip(("joint1", "joint2", "joint3"), t)), **dict(zip(JOINTS, g))})
        data.qpos[:] = 0
        for name, value in zip(coupling.tree.names[1:], coupling.configuration(t)):
            data.qpos[mj.joint(name).qposadr[0]] = value
        for name, value in zip(JOINTS, g):
            data.qpos[mj.joint(name).qposadr[0]] = value
        mujoco.mj_kinematics(mj, data)
        s_pos, s_mat = data.site("report_s").xpos, data.site("report_s").xmat.reshape(3, 3)
        for frame, ours in (("stylus", touch.stylus_pose(t, g)), ("stylus_tip", touch.stylus_tip_pose(t, g))):
            assert np.abs(urdf.get_transform(frame, "report_s") - ours).max() < 1e-12
            site = data.site(frame)
            assert np.abs(s_mat.T @ (site.xpos - s_pos) - ours[:3, 3]).max() < 1e-12
            assert np.abs(s_mat.T @ site.xmat.reshape(3, 3) - ours[:3, :3]).max() < 1e-12


# -- the load -----------------------------------------------------------------------------------

def test_gravity_with_the_stylus_is_the_closed_form_plus_the_gimbals_potential_gradient(touch):
    """Phantom.gravity(theta, gimbal) = the report's N(theta) (eqs 93-94) + the gradient of the
    gimbal links' potential (complex steps): 1e-12 N m; gimbal=None holds it at locked_at."""
    theta, gimbal = states(100, seed=6)
    report = touch.config.report
    got = touch.gravity(theta, gimbal)
    for t, g, torque in zip(theta, gimbal, got):
        assert np.abs(torque - (closed_form.gravity(t, report) + gimbal_gravity(t, g))).max() < 1e-12
    locked = np.array(GIMBAL_YAML["locked_at"], float)
    assert np.abs(touch.gravity(theta) - touch.gravity(theta, np.tile(locked, (100, 1)))).max() < 1e-12
    # the stylus's weight moves the arm's torques by up to tens of mN m: the test can fail
    assert np.abs(got - np.array([closed_form.gravity(t, report) for t in theta])).max() > 1e-3


def test_the_mass_matrix_carries_the_locked_stylus_as_three_rigid_bodies(touch):
    """M(theta) = the report's M (eqs 81-85) + sum over the gimbal links of m Jc^T Jc +
    Jw^T R I R^T Jw at locked_at, the Jacobians by complex steps of Ubitrack's kinematics and
    each link's inertia about the gimbal centre (SymPy): 1e-12 relative."""
    theta, _ = states(50, seed=7)
    locked = np.array(GIMBAL_YAML["locked_at"], float)
    report = touch.config.report
    for t in theta:
        expected = closed_form.mass_matrix(t, report) + gimbal_mass_matrix(t, locked)
        got = touch.mass_matrix(t)
        assert np.abs(got - expected).max() < 1e-12 * np.abs(expected).max()


# -- the drivers ----------------------------------------------------------------------------------

def test_the_drivers_gimbal_conventions():
    """Raw (the Touch-era drivers) is the identity; the fsuarez6 lineage's FireWire Omni publishes
    yaw = -g1 + pi, pitch = -g2 - 3 pi / 4, roll = -g3 - pi (omni_state.cpp lines 188-193),
    written here independently; rates carry no offsets."""
    _, gimbal = states(10, seed=8)
    names, raw = conventions.joint_state_from_gimbal(gimbal, prefix="left_")
    assert names == ["left_yaw", "left_pitch", "left_roll"] and np.array_equal(raw, gimbal)
    _, omni = conventions.joint_state_from_gimbal(gimbal, convention="omni_firewire")
    expected = np.stack([-gimbal[:, 0] + np.pi, -gimbal[:, 1] - 3 * np.pi / 4, -gimbal[:, 2] - np.pi], axis=1)
    assert np.abs(omni - expected).max() < 1e-15
    shuffled = ["roll", "waist", "pitch", "yaw"]
    position = np.stack([omni[:, 2], np.zeros(10), omni[:, 1], omni[:, 0]], axis=1)
    back = conventions.gimbal_from_joint_state(shuffled, position, convention="omni_firewire")
    assert np.abs(back - gimbal).max() < 1e-14
    _, rates = conventions.joint_state_from_gimbal(gimbal, convention="omni_firewire", rates=True)
    assert np.array_equal(rates, -gimbal)
    with pytest.raises(InvalidInputError) as error:
        conventions.gimbal_from_joint_state(["yaw", "pitch"], [0, 0])
    assert error.value.argument == "names"
    with pytest.raises(InvalidInputError) as error:
        conventions.joint_state_from_gimbal(gimbal, convention="omni")
    assert error.value.argument == "convention"


def test_hd_current_transform_is_the_stylus_pose_column_major_in_mm(touch):
    """HD_CURRENT_TRANSFORM's 16 numbers: the rotation's columns first, the translation (mm) at
    12..14, from OpenHaptics' origin (gimbal.yaml's openhaptics_shoulder less the shoulder's
    position (0, l2, -l1) in frame s, read here from the YAML), 1 at 15; to and from the
    stylus's pose (m)."""
    kinematics = yaml.safe_load((TOUCH / "kinematics.yaml").read_text())
    origin = np.array(GIMBAL_YAML["openhaptics_shoulder"]) - [0, kinematics["l2"], -kinematics["l1"]]
    theta, gimbal = states(5, seed=9)
    pose = touch.stylus_pose(theta[0], gimbal[0])
    flat = conventions.openhaptics_transform_from_pose(pose)
    assert np.array_equal(flat[0:3], pose[:3, 0]) and np.array_equal(flat[4:7], pose[:3, 1])
    assert np.allclose(flat[12:15], (pose[:3, 3] + origin) * 1000, rtol=1e-14) and flat[15] == 1 and flat[3] == 0
    at_zero = conventions.openhaptics_transform_from_pose(pose, origin=np.zeros(3))
    assert np.allclose(at_zero[12:15], pose[:3, 3] * 1000, rtol=1e-15)
    back = conventions.pose_from_openhaptics_transform(flat)
    assert np.abs(back - pose).max() < 1e-15
    batch = conventions.pose_from_openhaptics_transform(conventions.openhaptics_transform_from_pose(
        touch.stylus_pose(theta, gimbal)))
    assert batch.shape == (5, 4, 4)
    skewed = flat.copy()
    skewed[0] *= 1.1
    with pytest.raises(InvalidInputError) as error:
        conventions.pose_from_openhaptics_transform(skewed)
    assert error.value.argument == "transform"


@pytest.mark.chromium
def test_the_viewer_draws_the_stylus_where_its_pose_puts_it(tmp_path):
    """The exported page, rendered by chromium: a point on the stylus's back half (6 cm along its
    +z from the gimbal centre, placed by Pinocchio) is the stylus's light grey; with the stylus
    yawed away (g1 = 1.5 rad) the same pixel is not (the background)."""
    import pinocchio as pin

    from helpers import light_grey, patch, render
    from phantom_pin import describe, load
    from phantom_pin.viewer import Viewer

    robot = load(describe("touch"))
    theta, near, away = np.array([0.0, 0.5, 0.7]), np.zeros(3), np.array([1.5, 0.0, 0.0])
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, np.concatenate([theta, near]))
    point = data.oMf[robot.model.getFrameId("stylus")].act(np.array([0.0, 0.0, 0.06]))
    images = {}
    with Viewer(robot) as viewer:
        for name, gimbal in (("near", near), ("away", away)):
            viewer.show(theta, gimbal)
            images[name] = render(viewer.export_html(tmp_path / f"{name}.html"), tmp_path / f"{name}.png")
        with pytest.raises(InvalidInputError) as error:
            viewer.show(theta, [0.0, 0.0])
        assert error.value.argument == "gimbal"
    assert light_grey(patch(images["near"], point))
    assert not light_grey(patch(images["away"], point))


#: Gimbal angles inside the Touch's ranges, none zero: a sign error in the lock shows here.
LOCK = (0.3, -0.4, 0.5)


def _locked_touch():
    from phantom_pin import describe

    return describe("touch", overrides={f"locked_at.{i}": v for i, v in enumerate(LOCK)})


def test_the_arm_dynamics_hold_the_gimbal_at_a_nonzero_locked_at_as_the_six_joint_model():
    """The arm's dynamics hold the gimbal at locked_at, a nonzero one too: against Pinocchio's
    six-joint model (joint4..6 free, at q = LOCK), whose arm block of M and arm torques of
    gravity are the locked arm's, at 50 seeded states inside the stops; 1e-12 relative. The
    gravity differs by 2 % from the one at 0 (the test can see the lock's sign)."""
    import pinocchio as pin

    from phantom_pin import Phantom
    from phantom_pin.config.sampling import random_states
    from phantom_pin.dynamics.loader import load

    description = _locked_touch()
    arm, six = Phantom(description), load(description)
    theta = random_states(config.read("touch").limits, 50, seed=42)[0]
    for th in theta:
        q = np.concatenate([th, LOCK])
        gravity = pin.computeGeneralizedGravity(six.model, six.data, q)[:3]
        mass = pin.crba(six.model, six.data, q)[:3, :3]
        np.testing.assert_allclose(arm.gravity(th), gravity, rtol=0, atol=1e-12 * np.abs(gravity).max())
        np.testing.assert_allclose(arm.mass_matrix(th), mass, rtol=0, atol=1e-12 * np.abs(mass).max())
    at_zero = pin.computeGeneralizedGravity(six.model, six.data, np.concatenate([theta[0], [0, 0, 0]]))[:3]
    assert np.abs(at_zero - arm.gravity(theta[0])).max() > 1e-3 * np.abs(at_zero).max()


def test_the_mjcf_holds_the_gimbal_at_a_nonzero_locked_at():
    """The MJCF's lock equalities hold the gimbal at locked_at, a nonzero one too: MuJoCo's own
    residual of each <joint>_lock is zero with the gimbal at LOCK, and 2 LOCK at -LOCK."""
    mujoco = pytest.importorskip("mujoco")
    model = mujoco.MjModel.from_xml_string(_locked_touch().mjcf)
    data = mujoco.MjData(model)
    for sign in (1, -1):
        for joint, angle in zip(("joint4", "joint5", "joint6"), LOCK):
            data.qpos[model.joint(joint).qposadr[0]] = sign * angle
        mujoco.mj_forward(model, data)
        residual = {model.equality(data.efc_id[i]).name: data.efc_pos[i] for i in range(data.nefc)
                    if data.efc_type[i] == mujoco.mjtConstraint.mjCNSTR_EQUALITY}
        expected = [0.0, 0.0, 0.0] if sign == 1 else [-2 * a for a in LOCK]
        np.testing.assert_allclose([residual[f"joint{j}_lock"] for j in (4, 5, 6)], expected, rtol=0, atol=1e-12)


@pytest.mark.parametrize("index, beyond", [(1, "upper"), (1, "lower"), (2, "upper")])
def test_a_locked_at_outside_the_gimbals_range_is_refused(index, beyond):
    """A locked_at outside the gimbal's range is refused naming the joint and the angle; at the
    range's end it is taken. The ranges as gimbal.yaml states them (PyYAML)."""
    stated = yaml.safe_load((config.MODELS["touch"].config / "gimbal.yaml").read_text())["joints"]
    joint = f"joint{4 + index}"
    angle = stated[joint][beyond] + (1e-9 if beyond == "upper" else -1e-9)
    with pytest.raises(ParameterFileError, match=f"locked_at: {joint} at {angle!r} rad is outside its range"):
        config.read("touch", {f"locked_at.{index}": angle})
    assert config.read("touch", {f"locked_at.{index}": stated[joint][beyond]}).gimbal.locked_at[index] == \
        stated[joint][beyond]
