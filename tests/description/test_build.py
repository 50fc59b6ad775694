"""A configuration's description (description/build.py: describe, shipped, driver_urdf): the
generated files, names, prefixes, link numbers, and three tools.

And the Touch's URDF in the older ROS drivers' fixed convention (urdf/touch_driver.urdf,
drivers.FIXED_CONVENTION): their six joint_states drive it unchanged. Its link poses, in Pinocchio (mimic) and yourdfpy,
from joint_states written by the drivers' published formulas (waist = -angle1, shoulder =
angle2, elbow = angle3 - angle2, raw gimbal angles), equal ours in the report's convention
from the OpenHaptics angles they came from."""

import dataclasses
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
import yaml
import yourdfpy

from helpers import CONFIG, REPORT, relative_error
from phantom_pin import ParameterFileError, config
from phantom_pin.config import MODELS, files, models
from phantom_pin.description.build import describe, driver_urdf, links_yaml, shipped
from phantom_pin.report import appendix, closed_form
from references import driver as driver_reference

SHIPPED = MODELS["premium_1_5"]
URDF_PATH, SRDF_PATH = SHIPPED.urdf, SHIPPED.srdf

ACTUATED = ["joint1", "joint2", "joint3"]
# (joint, primary, multiplier) of the parallelogram, as designed in urdf/phantom_macro.xacro
PASSIVE = [("crank_pin_a", "joint3", -1.0), ("crank_pin_b", "joint2", 1.0),
           ("forearm_pin_a", "joint2", -1.0), ("forearm_pin_b", "joint3", 1.0)]
SEGMENT_LINKS = ["turret_link", "upper_arm_link", "crank_link", "lower_bar_link", "forearm_link"]
PIN_LINKS = {"crank_pin_link": "crank_link", "forearm_pin_link": "lower_bar_link"}  # pin: mass donor


@pytest.fixture(scope="module")
def urdf_root():
    return ET.parse(URDF_PATH).getroot()


@pytest.fixture(scope="module")
def mimic_model():
    model = pin.buildModelFromUrdf(str(URDF_PATH), mimic=True)
    pin.loadRotorParameters(model, str(SRDF_PATH), False)
    return model


@pytest.mark.parametrize("name", models())
def test_committed_files_match_a_fresh_xacro_run(name):
    """Every model's committed URDF, SRDF, MJCF, scene and (report-form) links.yaml equal
    what its configuration generates now: a stale file fails here."""
    model, fresh = MODELS[name], describe(name)
    hint = "run the regeneration in robots/phantom_description/README.md"
    for kind in ("urdf", "srdf", "mjcf", "scene"):
        assert getattr(model, kind).read_text() == getattr(fresh, kind), f"{name} {kind}: {hint}"
    if model.links_file is not None:
        assert model.links_file.read_text() == links_yaml(fresh.config), f"{name} links: {hint}"
    committed = shipped(name)
    assert (committed.urdf, committed.srdf, committed.mjcf) == (fresh.urdf, fresh.srdf, fresh.mjcf)


def test_the_xacro_alone_reads_the_committed_links(tmp_path):
    """Plain xacro on the top-level xacro with its default (committed) files gives the
    committed URDF, banner aside: links.yaml is what a ROS user's xacro reads."""
    import xacro

    for name in models():
        model = MODELS[name]
        plain = xacro.process_file(str(model.urdf_xacro), mappings={"model": name}).documentElement.toprettyxml(
            indent="  ")
        committed = model.urdf.read_text()
        assert committed[committed.index("<robot"):].strip() == plain.strip(), name


def test_a_configuration_is_read_once_into_every_model(tmp_path, monkeypatch):
    """describe() reads each parameter file once and gives the URDF, SRDF and MJCF; Phantom,
    load() and Device take that one result without reading or generating again."""
    import shutil

    from phantom_pin import Device, Phantom, load
    config = tmp_path / "config"
    shutil.copytree(SHIPPED.config, config)
    reads = []
    original = files.read_yaml
    monkeypatch.setattr(files, "read_yaml", lambda path: reads.append(path.name) or original(path))
    description = describe(config, overrides={"l1": 0.2096})
    # every file once; the optional ones (a gimbal.yaml) only where the model has them
    assert sorted(reads) == sorted(name for arg, name in files.FILES.items() if arg not in files.OPTIONAL)
    phantom = Phantom(description)
    robot = load(description)
    device = Device(phantom)
    assert len(reads) == len(files.FILES) - len(files.OPTIONAL)  # nothing read again
    assert phantom.description is description and device.config.kinematics.l1 == 0.2096
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, np.zeros(3))
    assert data.oMf[robot.model.getFrameId("elbow")].translation[0] == pytest.approx(0.2096, abs=1e-15)
    assert 'name="elbow" class="frame" pos="0.2096 0 0"' in description.mjcf


def test_prefix_reaches_every_name():
    left = describe(prefix="left_")
    root = ET.fromstring(left.urdf)
    names = [e.get("name") for e in root.iter() if e.tag in ("link", "joint", "material") and e.get("name")]
    assert names and all(n.startswith("left_") for n in names)
    references = [e.get("link") for e in root.iter() if e.tag in ("parent", "child")]
    references += [e.get("joint") for e in root.iter("mimic")]
    assert all(r.startswith("left_") for r in references)
    model = pin.buildModelFromXML(left.urdf, mimic=True)
    assert [model.names[i] for i in range(1, 4)] == ["left_joint1", "left_joint2", "left_joint3"]
    assert model.existFrame("left_tip") and model.existFrame("left_report_s")
    srdf = ET.fromstring(left.srdf)
    srdf_names = [j.get("name") for j in srdf.iter("joint")]
    assert srdf_names and all(n.startswith("left_") for n in srdf_names)


def test_joints_are_the_report_thetas_and_the_parallelogram_mimics(urdf_root):
    joints = {j.get("name"): j for j in urdf_root.findall("joint")}
    for name, axis in zip(ACTUATED, ["0 0 1", "0 -1 0", "0 -1 0"]):
        assert joints[name].get("type") == "revolute" and joints[name].find("mimic") is None
        assert joints[name].find("axis").get("xyz") == axis
    for name, primary, multiplier in PASSIVE:
        mimic = joints[name].find("mimic")
        assert (mimic.get("joint"), float(mimic.get("multiplier")), float(mimic.get("offset"))) \
            == (primary, multiplier, 0.0)
    urdf = yourdfpy.URDF.load(str(URDF_PATH))
    assert urdf.actuated_joint_names == ACTUATED


def test_mimic_model_has_three_dofs_and_the_rotor_armature(mimic_model):
    a, limits = CONFIG.actuation, CONFIG.limits
    assert (mimic_model.nq, mimic_model.nv) == (3, 3)
    np.testing.assert_allclose(mimic_model.armature, [a.motor.rotor_inertia * r**2 for r in a.ratios], rtol=1e-12)
    np.testing.assert_array_equal(mimic_model.lowerPositionLimit, limits.lower)
    np.testing.assert_array_equal(mimic_model.upperPositionLimit, limits.upper)


def _inertials(root):
    for link in root.iter("link"):
        inertial = link.find("inertial")
        if inertial is not None:
            i = inertial.find("inertia").attrib
            tensor = np.array([[float(i["ixx"]), float(i["ixy"]), float(i["ixz"])],
                               [float(i["ixy"]), float(i["iyy"]), float(i["iyz"])],
                               [float(i["ixz"]), float(i["iyz"]), float(i["izz"])]])
            com = np.array([float(x) for x in inertial.find("origin").get("xyz").split()])
            yield link.get("name"), float(inertial.find("mass").get("value")), com, tensor


def test_every_link_inertia_is_physical(urdf_root):
    links = {name: (mass, tensor) for name, mass, _, tensor in _inertials(urdf_root)}
    assert sorted(links) == sorted(["base_link"] + SEGMENT_LINKS + list(PIN_LINKS))  # no massless body
    for name, (mass, tensor) in links.items():
        moments = np.linalg.eigvalsh(tensor)
        assert mass > 0 and moments.min() > 0, name
        a, b, c = np.sort(moments)
        assert c <= a + b, f"{name}: triangle inequality fails at the COM"


def test_link_inertias_give_back_the_report_values(urdf_root):
    """Undo the xacro's conversion: URDF (COM, base axes) to the report's (origin, report axes).

    Each hinge pin's mass sits at its pivot, a point of its donor link: added back to the
    donor (as a point mass, by Pinocchio's spatial-inertia sum), the donor is the report's
    segment again. The pins' vertical moments add back to the turret's.
    """
    p, armature = REPORT, CONFIG.actuation.armature
    to_report = np.array([[0, 1, 0], [0, 0, 1], [1, 0, 0]])  # base (x, y, z) = report (z, x, y)
    armature2, armature3 = armature[1], armature[2]
    expected = {  # link: (mass, report inertia about the point below, point in report axes)
        "forearm_link": (p.ma, np.diag([p.Iaxx, p.Iayy, p.Iazz]), None),
        "lower_bar_link": (p.mc, np.diag([p.Icxx, p.Icyy, p.Iczz]), None),
        "upper_arm_link": (p.mbe, np.diag([p.Ibexx - armature2, p.Ibeyy, p.Ibezz]), np.zeros(3)),
        "crank_link": (p.mdf, np.diag([p.Idfxx - armature3, p.Idfyy, p.Idfzz]), np.zeros(3)),
    }
    coms = {"upper_arm_link": [0, 0, p.l5], "crank_link": [0, p.l6, 0],
            "lower_bar_link": [0, 0, p.l1 / 2], "forearm_link": [0, p.l3 - p.l2 / 2, 0]}
    links = {name: pin.Inertia(mass, com, tensor) for name, mass, com, tensor in _inertials(urdf_root)}
    pivots = {"crank_pin_link": np.array([0, 0, -p.l3]),     # in crank_link (base axes)
              "forearm_pin_link": np.array([p.l1, 0, 0])}   # in lower_bar_link
    vertical = 0.0
    for pin_link, donor in PIN_LINKS.items():
        pin_inertia = links.pop(pin_link)
        vertical += pin_inertia.inertia[2, 2]
        links[donor] = links[donor] + pin.Inertia(pin_inertia.mass, pivots[pin_link], np.zeros((3, 3)))
    links.pop("base_link")  # the fixed housing, not a segment of the report (test_gazebo.py checks it)
    turret = links.pop("turret_link")
    assert turret.inertia[2, 2] + vertical + armature[0] == pytest.approx(p.Ibaseyy, rel=1e-12)
    for name, inertia in links.items():
        report_mass, report_inertia, about = expected[name]
        com_report = to_report @ inertia.lever
        np.testing.assert_allclose(com_report, coms[name], atol=1e-15, err_msg=name)
        tensor = to_report @ inertia.inertia @ to_report.T
        if about is not None:  # parallel-axis theorem from the COM to the shoulder
            tensor = tensor + inertia.mass * (com_report @ com_report * np.eye(3) - np.outer(com_report, com_report))
        assert inertia.mass == pytest.approx(report_mass, rel=1e-15)
        np.testing.assert_allclose(tensor, report_inertia, rtol=1e-12, atol=1e-18, err_msg=name)


def test_crba_equals_the_report_mass_matrix(mimic_model, states):
    data = mimic_model.createData()
    theta = states[0]
    crba = np.array([pin.crba(mimic_model, data, q) for q in theta])
    crba = np.triu(crba) + np.swapaxes(np.triu(crba, 1), -1, -2)
    assert relative_error(crba, closed_form.mass_matrix(theta, REPORT)) < 1e-9


def test_rnea_equals_the_appendix_torques_to_their_printed_precision(mimic_model, states):
    data = mimic_model.createData()
    theta, dtheta, ddtheta = states
    rnea = np.array([pin.rnea(mimic_model, data, *s) for s in zip(theta, dtheta, ddtheta)])
    printed, bound = appendix.torques(theta, dtheta, ddtheta)
    # the URDF holds eq. 41's Iayy = 0.001843e-4, the appendix used 0.0018e-4: allow for that
    # difference, 0.043e-7 kg m^2 typed here (tau is linear in Iayy), not for the code's value
    as_appendix = dataclasses.replace(REPORT, Iayy=0.0018e-4)
    rounded = dataclasses.replace(as_appendix, Iayy=0.0018e-4 + 0.043e-7)
    bound += np.abs(closed_form.inverse_dynamics(theta, dtheta, ddtheta, rounded)
                    - closed_form.inverse_dynamics(theta, dtheta, ddtheta, as_appendix))
    assert np.all(np.abs(rnea - printed) <= bound + 1e-15)


def test_yourdfpy_forward_kinematics_is_eq10_and_pinocchio(mimic_model, states):
    urdf = yourdfpy.URDF.load(str(URDF_PATH))
    data = mimic_model.createData()
    s, tip = mimic_model.getFrameId("report_s"), mimic_model.getFrameId("tip")
    worst_report = worst_pinocchio = 0.0
    for theta in states[0]:
        urdf.update_cfg(theta)
        g = np.linalg.inv(urdf.get_transform("report_s")) @ urdf.get_transform("tip")
        pin.framesForwardKinematics(mimic_model, data, theta)
        g_pin = data.oMf[s].actInv(data.oMf[tip]).homogeneous
        worst_report = max(worst_report, np.abs(g - closed_form.forward_kinematics(theta, REPORT)).max())
        worst_pinocchio = max(worst_pinocchio, np.abs(g - g_pin).max())
    assert worst_report < 1e-9 and worst_pinocchio < 1e-9


def test_parallelogram_closes_in_the_mimic_free_model(urdf_root, states):
    """Set the passive joints from theta by the URDF's mimic tags, then meet at the elbow."""
    tree = pin.buildModelFromUrdf(str(URDF_PATH), mimic=False)
    data = tree.createData()
    mimic = {j.get("name"): (j.find("mimic").get("joint"), float(j.find("mimic").get("multiplier")))
             for j in urdf_root.iter("joint") if j.find("mimic") is not None}
    l3 = REPORT.l3
    worst = 0.0
    for theta in states[0]:
        angles = dict(zip(ACTUATED, theta))
        q = np.array([angles[n] if n in angles else mimic[n][1] * angles[mimic[n][0]]
                      for n in tree.names[1:]])
        pin.framesForwardKinematics(tree, data, q)
        through_upper_arm = data.oMf[tree.getFrameId("elbow")].translation
        through_lower_bar = data.oMf[tree.getFrameId("forearm_link")].act(np.array([0, 0, l3]))
        worst = max(worst, np.abs(through_upper_arm - through_lower_bar).max())
        # the lower bar stays parallel to the upper arm, the forearm to the crank
        for a, b in (("lower_bar_link", "upper_arm_link"), ("forearm_link", "crank_link")):
            rotation = data.oMf[tree.getFrameId(a)].rotation.T @ data.oMf[tree.getFrameId(b)].rotation
            worst = max(worst, np.abs(rotation - np.eye(3)).max())
    assert worst < 1e-9


def test_report_frames_sit_where_the_report_puts_them(mimic_model):
    data = mimic_model.createData()
    pin.framesForwardKinematics(mimic_model, data, np.zeros(3))
    p = REPORT
    dynamics = data.oMf[mimic_model.getFrameId("report_dynamics")]
    s = data.oMf[mimic_model.getFrameId("report_s")]
    # report y is up (gravity along -y, eqs 34, 45), report z forward, x left (REP-103 base)
    np.testing.assert_allclose(dynamics.rotation, [[0, 0, 1], [1, 0, 0], [0, 1, 0]], atol=1e-15)
    np.testing.assert_allclose(dynamics.translation, 0, atol=1e-15)
    # the dynamics frame's origin (the shoulder) is at (0, l2, -l1) in s (eqs 4-5, 27)
    np.testing.assert_allclose(s.actInv(dynamics).translation, [0, p.l2, -p.l1], atol=1e-15)
    np.testing.assert_allclose(mimic_model.gravity.linear, [0, 0, -p.g])


def test_srdf_postures_are_inside_the_limits(limits):
    srdf = ET.parse(SRDF_PATH).getroot()
    postures = {g.get("name"): [float(j.get("value")) for j in g.iter("joint")] for g in srdf.iter("group_state")}
    assert set(postures) == {"zero", "resting"}
    assert postures["zero"] == [0.0, 0.0, 0.0]
    for values in postures.values():
        assert np.all(limits[0] <= values) and np.all(np.array(values) <= limits[1])


def test_shipped_checks_the_committed_urdf(tmp_path, monkeypatch):
    """shipped() reads the committed files: a committed URDF with a non-physical link is
    refused, naming the file."""
    from phantom_pin.description.build import _shipped, shipped

    model = config.MODELS["premium_1_5"]
    text = model.urdf.read_text()
    bad = tmp_path / "premium_1_5.urdf"
    bad.write_text(text.replace('<mass value="0.0202"/>', '<mass value="-0.0202"/>', 1))
    assert bad.read_text() != text
    monkeypatch.setitem(config.MODELS, "premium_1_5", dataclasses.replace(model, urdf=bad))
    _shipped.cache_clear()
    try:
        with pytest.raises(ParameterFileError, match=str(bad)):
            shipped("premium_1_5")
    finally:
        _shipped.cache_clear()


DRIVER_URDF = MODELS["touch"].urdf.with_name("touch_driver.urdf")


TOUCH = MODELS["touch"].config


DRIVER_JOINTS = ("waist", "shoulder", "elbow", "yaw", "pitch", "roll")


OURS = ("joint1", "joint2", "joint3", "joint4", "joint5", "joint6")


def openhaptics_states(n: int, seed: int) -> np.ndarray:
    """``n`` seeded OpenHaptics angle sets (joint angles O1..O3, raw gimbal O4..O6, rad) inside
    the Touch's stops and gimbal ranges (read from its YAML): the posture a driver reads."""
    limits = yaml.safe_load((TOUCH / "joint_limits.yaml").read_text())["stops"]
    gimbal = yaml.safe_load((TOUCH / "gimbal.yaml").read_text())["joints"]
    rng = np.random.default_rng(seed)
    theta = rng.uniform([limits[j]["lower"] for j in OURS[:3]], [limits[j]["upper"] for j in OURS[:3]], (8 * n, 3))
    keep = ((theta[:, 1] - theta[:, 2] <= limits["theta2_minus_theta3_max"])
            & (theta[:, 2] - theta[:, 1] <= limits["theta3_minus_theta2_max"]))
    g = rng.uniform([gimbal[j]["lower"] for j in OURS[3:]], [gimbal[j]["upper"] for j in OURS[3:]], (n, 3))
    theta = theta[keep][:n]
    return np.concatenate([-theta[:, :1], theta[:, 1:], g], axis=1)  # O1 = -theta1


def driver_joint_states(o: np.ndarray) -> dict[str, float]:
    """What the older drivers publish for OpenHaptics' angles ``o``: sawSensablePhantom's formula
    (driver_reference.published, its source lines; the fsuarez6 lineage's arm is the same)."""
    names, positions = driver_reference.published("sawsensablephantom", o[:3], o[3:])
    assert names == list(DRIVER_JOINTS)
    return dict(zip(names, positions))


def report_state(o: np.ndarray) -> dict[str, float]:
    """Our joints of the same angles: theta = (-O1, O2, O3), joint4..joint6 = the raw gimbal."""
    return dict(zip(OURS, (-o[0], o[1], o[2], o[3], o[4], o[5])))


def pinocchio_links(urdf: str, state: dict[str, float]) -> dict[str, np.ndarray]:
    model = pin.buildModelFromXML(urdf, mimic=True)
    data = model.createData()
    q = pin.neutral(model)
    for name, value in state.items():
        q[model.joints[model.getJointId(name)].idx_q] = value
    pin.framesForwardKinematics(model, data, q)
    return {f.name: data.oMf[i].homogeneous for i, f in enumerate(model.frames) if f.type == pin.FrameType.BODY}


def test_the_committed_driver_urdf_is_fresh():
    assert DRIVER_URDF.read_text() == driver_urdf("touch")


def test_the_drivers_joint_states_move_every_link_as_ours_in_pinocchio_and_yourdfpy():
    """Every link's pose in base_link, 1e-12 m and 1e-12 in rotation, over 100 states; the
    driver URDF's independent joints are exactly the drivers' six."""
    driver, ours = DRIVER_URDF.read_text(), MODELS["touch"].urdf.read_text()
    robot = yourdfpy.URDF.load(str(DRIVER_URDF), build_scene_graph=True, load_meshes=False)
    assert tuple(robot.actuated_joint_names) == DRIVER_JOINTS
    reduced = pin.buildModelFromXML(driver, mimic=True)
    assert reduced.nq == 6 and {reduced.names[i] for i in range(1, reduced.njoints)} >= set(DRIVER_JOINTS)
    for o in openhaptics_states(100, seed=11):
        state = driver_joint_states(o)
        expected = pinocchio_links(ours, report_state(o))
        got = pinocchio_links(driver, state)
        assert set(got) == set(expected)
        robot.update_cfg(state)
        for link, pose in expected.items():
            assert np.abs(got[link] - pose).max() < 1e-12, link
            assert np.abs(robot.get_transform(link, "base_link") - pose).max() < 1e-12, link


def test_no_rounded_elbow_and_check_urdf_passes(tmp_path):
    """The lineage's URDFs round the elbow's rpy to -1.5; ours has no rotated joint origin in
    the arm at all; urdfdom parses the prefixed file."""
    assert "-1.5 " not in DRIVER_URDF.read_text()
    urdf = tmp_path / "driver.urdf"
    urdf.write_text(driver_urdf("touch", prefix="left_"))
    tool = Path(sys.executable).parent / "check_urdf"
    result = subprocess.run([str(tool if tool.exists() else "check_urdf"), str(urdf)], capture_output=True, text=True)
    assert result.returncode == 0 and "root Link: left_base_link" in result.stdout, result.stdout + result.stderr


def test_plain_xacro_with_convention_driver_gives_the_committed_file(tmp_path):
    """xacro phantom.urdf.xacro model:=touch convention:=driver (its default parameter files) is
    the committed driver URDF (comments aside); another convention, the drivers' convention of a
    model without a stylus gimbal (no driver publishes it) and an unknown model are refused,
    each naming what it refuses."""
    top = MODELS["touch"].urdf_xacro
    xacro = Path(sys.executable).parent / "xacro"

    def run(*arguments: str) -> subprocess.CompletedProcess:
        return subprocess.run([str(xacro), str(top), *arguments], capture_output=True, text=True, cwd=top.parent)

    result = run("model:=touch", "convention:=driver")
    assert result.returncode == 0, result.stderr
    assert ET.canonicalize(result.stdout, strip_text=True) == ET.canonicalize(DRIVER_URDF.read_text(), strip_text=True)
    for arguments, message in ((("model:=touch", "convention:=ros"), "convention must be report or driver"),
                               (("convention:=driver",), "written for the Touch (model:=touch)"),
                               (("model:=omni",), "model must be one of premium_1_5, premium_1_5_cad, touch")):
        bad = run(*arguments)
        assert bad.returncode != 0 and message in bad.stderr, (arguments, bad.stderr)


def test_a_model_whose_drivers_publish_no_convention_is_refused_in_one_line(capsys, tmp_path):
    """Only the Touch takes convention:=driver: the Premium is refused, naming the model, before
    xacro runs, and nothing is written."""
    from phantom_pin import InvalidInputError
    from phantom_pin.cli import main

    try:
        driver_urdf("premium_1_5")
    except InvalidInputError as error:
        assert error.argument == "model" and "Touch" in str(error)
    else:
        raise AssertionError("driver_urdf('premium_1_5') was not refused")
    target = tmp_path / "d.urdf"
    assert main(["urdf", "--convention", "driver", "-o", str(target)]) == 2
    assert len(capsys.readouterr().err.strip().splitlines()) == 1 and not target.exists()
