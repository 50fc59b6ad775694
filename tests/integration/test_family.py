"""Every model of the family (phantom_pin.models()), each as its tool's own test would have it:
urdfdom's check_urdf on plain xacro with and without a prefix (Universal Robots' description
test), every MuJoCo scene stepped under pseudo-random control and the package's layout
(mujoco_menagerie's model and model-directory tests), the
joints load() gives (example-robot-data's test), and the tip against eq. 10 written here with
the model's own lengths, read from its kinematics.yaml."""

import shutil
import subprocess
import sys
from pathlib import Path

import mujoco
import numpy as np
import pinocchio as pin
import pytest
import yaml

from phantom_pin import config, describe, load
from phantom_pin._paths import DESCRIPTION_DIR
from phantom_pin.config import MODELS, models
from phantom_pin.config.sampling import sample_postures

PREFIXES = ("", "left_")


def _tool(name: str) -> str:
    path = Path(sys.executable).parent / name
    found = str(path) if path.exists() else shutil.which(name)
    assert found, f"{name} ships with the test dependencies (xacro, pin's urdfdom)"
    return found


@pytest.mark.parametrize("prefix", PREFIXES)
@pytest.mark.parametrize("name", models())
def test_plain_xacro_of_every_model_passes_check_urdf(name, prefix, tmp_path):
    """xacro on the committed top-level xacro with model:=NAME (its default parameter files),
    then check_urdf."""
    model = MODELS[name]
    urdf = tmp_path / f"{name}.urdf"
    arguments = [f"prefix:={prefix}"] if prefix else []
    result = subprocess.run([_tool("xacro"), str(model.urdf_xacro), *model.xacro_args, *arguments, "-o", str(urdf)],
                            capture_output=True, text=True, cwd=model.urdf_xacro.parent)
    assert result.returncode == 0, result.stderr
    result = subprocess.run([_tool("check_urdf"), str(urdf)], capture_output=True, text=True)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "Successfully Parsed XML" in result.stdout
    assert f"root Link: {prefix}base_link has 3 child(ren)" in result.stdout
    children = [line.split(":", 1)[1].strip() for line in result.stdout.splitlines() if "child(" in line]
    # a stylus gimbal (gimbal.yaml) adds yaw_link, pitch_link, stylus_link and the stylus frames
    gimbal = (model.config / "gimbal.yaml").exists()
    assert len(children) == 12 + 5 * gimbal and all(child.startswith(prefix) for child in children), children
    assert {child[len(prefix):] for child in children} >= {"turret_link", "forearm_link", "tip", "report_s"}


def test_the_package_readme_xacro_commands_give_the_committed_files(tmp_path):
    """Each `xacro ...` line of robots/phantom_description/README.md, run as written from urdf/
    (its -o sent to a temporary folder): a file named as a committed one equals it (comments
    aside), and the prefixed one names every joint with its prefix."""
    import xml.etree.ElementTree as ET

    folder = MODELS["premium_1_5"].urdf_xacro.parent
    readme = (folder.parent / "README.md").read_text()
    lines = [line.split(None, 1)[1] for line in readme.splitlines() if line.startswith("    xacro ")]
    assert len(lines) == 4, lines
    for line in lines:
        *arguments, flag, output = line.split("#")[0].split()
        assert flag == "-o", line
        result = subprocess.run([_tool("xacro"), *arguments, "-o", str(tmp_path / output)],
                                capture_output=True, text=True, cwd=folder)
        assert result.returncode == 0, (line, result.stderr)
        written = (tmp_path / output).read_text()
        committed = next((p for p in (folder / output, folder.parent / "srdf" / output) if p.is_file()), None)
        if committed is not None:
            assert ET.canonicalize(written, strip_text=True) == \
                ET.canonicalize(committed.read_text(), strip_text=True), line
        else:
            joints = [j.get("name") for j in ET.fromstring(written).iter("joint")]
            assert joints and all(j.startswith("left_") for j in joints), line


SCENES = sorted((DESCRIPTION_DIR / "mjcf").glob("scene*.xml"))


def test_the_package_has_what_menagerie_asks_of_each_model():
    """mujoco_menagerie's layout test (README, LICENSE, CHANGELOG, a scene*.xml), for one package
    holding three models: LICENSE is the project's and package.xml's licence, every model has its
    README section naming its config folder and its scene, and every scene*.xml is a model's."""
    package = DESCRIPTION_DIR
    root = package.parent.parent
    assert (package / "LICENSE").read_text() == (root / "LICENSE").read_text()
    assert (root / "LICENSE").read_text().startswith("BSD 3-Clause License")
    assert "<license>BSD-3-Clause</license>" in (package / "package.xml").read_text()
    assert (package / "CHANGELOG.md").read_text().startswith("# Changelog of phantom_description")
    readme = (package / "README.md").read_text()
    for name in models():
        assert f"\n### `{name}`" in readme, f"no README section for {name}"
        section = readme.split(f"\n### `{name}`")[1].split("\n#")[0]
        scene = MODELS[name].scene
        assert scene.is_file() and f"mjcf/{scene.name}" in section, name
        assert "Numbers:" in section and "plain import" in section, name
    assert SCENES == sorted(MODELS[name].scene for name in models())


def _halton_control(model: mujoco.MjModel, data: mujoco.MjData, step: int) -> None:
    """mujoco_menagerie's pseudo-random control (test/model_test.py): actuator j at step i is
    the ctrlrange's centre plus its half-width times 2 h - 1, h the Halton sequence of base j + 2."""
    for j in range(model.nu):
        low, high = model.actuator_ctrlrange[j]
        data.ctrl[j] = 0.5 * (low + high) + 0.5 * (high - low) * (2 * mujoco.mju_Halton(step, j + 2) - 1)


@pytest.mark.parametrize("scene", SCENES, ids=lambda path: path.name)
def test_every_scene_steps_one_second_under_pseudo_random_control_without_a_warning(scene):
    """mujoco_menagerie's model test on every mjcf/scene*.xml: from the default state, 1 s of the
    model's timestep under its Halton controls over the full control range (which reach the stops),
    then again under seeded uniform noise of half the range; no MuJoCo warning counter moves."""
    model = mujoco.MjModel.from_xml_path(str(scene))
    data = mujoco.MjData(model)
    assert model.nu == 3 and model.opt.timestep == 0.001 and model.actuator_ctrllimited.all()
    rng = np.random.default_rng(17)
    low, high = model.actuator_ctrlrange.T
    controls = (lambda step: _halton_control(model, data, step),
                lambda step: data.ctrl.__setitem__(slice(None), rng.uniform(low, high) * 0.5))
    for control in controls:
        mujoco.mj_resetData(model, data)
        step = 0
        while data.time < 1.0 - 0.5 * model.opt.timestep:
            control(step)
            mujoco.mj_step(model, data)
            step += 1
        assert step == 1000 and data.time == pytest.approx(1.0)
        assert [data.warning[i].number for i in range(len(data.warning))] == [0] * len(data.warning)
        assert np.isfinite(data.qpos).all() and np.isfinite(data.qvel).all()
        assert np.abs(data.qvel).max() > 0  # it moved


@pytest.mark.parametrize("name", models())
def test_load_gives_the_three_report_joints_the_frames_and_the_srdf_postures(name):
    robot = load(describe(name))
    limits = yaml.safe_load((MODELS[name].config / "joint_limits.yaml").read_text())
    gimbal_file = MODELS[name].config / "gimbal.yaml"
    # a stylus gimbal's passive joints follow theta (the Touch's): its ranges are gimbal.yaml's
    gimbal = yaml.safe_load(gimbal_file.read_text())["joints"] if gimbal_file.exists() else {}
    limits.update(gimbal)
    assert (robot.model.nq, robot.model.nv) == (3 + len(gimbal), 3 + len(gimbal))
    assert list(robot.model.names) == ["universe", "joint1", "joint2", "joint3",  # then the mimic joints
                                       "crank_pin_a", "crank_pin_b", "forearm_pin_a", "forearm_pin_b", *gimbal]
    stylus = ("stylus", "stylus_tip") if gimbal else ()
    for frame in ("base_link", "report_s", "report_dynamics", "tip", "elbow", *stylus):
        assert robot.model.existFrame(frame), frame
    for joint, lower, upper in zip(("joint1", "joint2", "joint3", *gimbal), robot.model.lowerPositionLimit,
                                   robot.model.upperPositionLimit):
        assert (lower, upper) == (limits[joint]["lower"], limits[joint]["upper"])
    rest = [0.0] * len(gimbal)  # the SRDF's postures set the arm: the gimbal stays at its zero
    for posture, theta in limits["postures"].items():
        np.testing.assert_array_equal(robot.model.referenceConfigurations[posture], [*theta, *rest])
    np.testing.assert_array_equal(robot.q0, [*limits["postures"]["resting"], *rest])


@pytest.mark.parametrize("name", models())
def test_every_tip_follows_eq10_with_its_own_lengths(name):
    """The tip in report_s, by Pinocchio on the model's URDF (describe()'s, equal to the committed one),
    against eq. 10 (the report's g_st position: x = s1 (l1 c2 + l2 s3), y = l2 - l2 c3 + l1 s2,
    z = -l1 + c1 (l1 c2 + l2 s3)) with l1, l2 from the model's kinematics.yaml, at 500 seeded
    postures inside its stops (1e-12 m)."""
    lengths = yaml.safe_load((MODELS[name].config / "kinematics.yaml").read_text())
    l1, l2 = lengths["l1"], lengths["l2"]
    robot = load(describe(name))
    data = robot.model.createData()
    thetas = sample_postures(config.read(name).limits, 500, np.random.default_rng(3), draws=2000)
    assert len(thetas) == 500
    for theta in thetas:
        pin.framesForwardKinematics(robot.model, data, np.concatenate([theta, np.zeros(robot.model.nq - 3)]))
        tip = data.oMf[robot.model.getFrameId("tip")]
        s = data.oMf[robot.model.getFrameId("report_s")]
        position = (s.actInv(tip)).translation
        t1, t2, t3 = theta
        reach = l1 * np.cos(t2) + l2 * np.sin(t3)
        expected = [np.sin(t1) * reach, l2 - l2 * np.cos(t3) + l1 * np.sin(t2), -l1 + np.cos(t1) * reach]
        np.testing.assert_allclose(position, expected, rtol=0, atol=1e-12)


@pytest.mark.parametrize("name", models())
def test_the_mjcfs_contact_excludes_are_the_srdfs_disabled_pairs(name):
    """MuJoCo excludes only parent-child pairs by itself: every pair the SRDF disables
    ("Adjacent" and "Never") must be an MJCF exclude, and no other."""
    import xml.etree.ElementTree as ET

    fresh = describe(name)  # generated now: the committed files are compared with it elsewhere
    srdf = ET.fromstring(fresh.srdf)
    disabled = {frozenset((p.get("link1"), p.get("link2"))) for p in srdf.iter("disable_collisions")}
    mjcf = ET.fromstring(fresh.mjcf)
    excluded = [frozenset((e.get("body1"), e.get("body2"))) for e in mjcf.iter("exclude")]
    assert len(excluded) == len(set(excluded)) and set(excluded) == disabled
    assert {reason.get("reason") for reason in srdf.iter("disable_collisions")} == {"Adjacent", "Never"}


@pytest.mark.parametrize("name", models())
def test_the_fresh_mjcfs_motors_are_limited_to_the_yamls_torque(name):
    """Each motor of the generated MJCF limits both its control and its force to ± the
    actuator torque of actuation.yaml (the motor's continuous torque at its shaft, or the
    joint_torque_limit without motor data), and the options follow mjcf.yaml."""
    actuation = yaml.safe_load((MODELS[name].config / "actuation.yaml").read_text())
    settings = yaml.safe_load((MODELS[name].config / "mjcf.yaml").read_text())
    model = mujoco.MjModel.from_xml_string(describe(name, robot_file="phantom.xml").mjcf)
    for i, joint in enumerate(("joint1", "joint2", "joint3")):
        torque = (actuation["joint_torque_limit"][joint] if actuation["motor"] is None
                  else actuation["motor"]["max_continuous_torque"])
        np.testing.assert_array_equal(model.actuator_ctrlrange[i], [-torque, torque])
        np.testing.assert_array_equal(model.actuator_forcerange[i], [-torque, torque])
        assert model.actuator_forcelimited[i] and model.actuator_ctrllimited[i]
    assert model.opt.timestep == settings["timestep"]
    assert model.opt.integrator == getattr(mujoco.mjtIntegrator, f"mjINT_{settings['integrator'].upper()}")


def test_every_mjcf_describe_accepts_loads_in_mujoco():
    """Seeded overrides (each segment's mass and inertias x 0.8..1.5 together, BE's centre of
    mass x 0.8..1.2, the lengths x 0.9..1.1), and the triangle's boundary case that once passed our
    check and not MuJoCo's: whatever describe() accepts, MuJoCo loads, and each refusal is the
    physical check's."""
    from phantom_pin import ParameterFileError

    physical = yaml.safe_load((MODELS["premium_1_5"].config / "physical_parameters.yaml").read_text())
    kinematics = yaml.safe_load((MODELS["premium_1_5"].config / "kinematics.yaml").read_text())
    rng = np.random.default_rng(23)
    cases = [{"segment_a.inertia.xx": 4.8824300001e-05}]
    for _ in range(12):
        case = {k: v * rng.uniform(0.9, 1.1) for k, v in kinematics.items()}
        for segment in ("segment_a", "segment_c", "segment_be", "segment_df"):
            factor = rng.uniform(0.8, 1.5)
            case[f"{segment}.mass"] = physical[segment]["mass"] * factor
            case.update({f"{segment}.inertia.{axis}": value * factor
                         for axis, value in physical[segment]["inertia"].items()})
            if segment == "segment_be":  # DF's inertia about the shoulder pins its centre of mass
                case[f"{segment}.com"] = physical[segment]["com"] * rng.uniform(0.8, 1.2)
        cases.append(case)
    loaded = 0
    for case in cases:
        try:
            text = describe("premium_1_5", overrides=case, robot_file="phantom.xml").mjcf
        except ParameterFileError as error:
            assert "inertia" in str(error) or "mass" in str(error), error
            continue
        mujoco.MjModel.from_xml_string(text)
        loaded += 1
    assert loaded >= 6, loaded
