"""phantom-pin's model commands (cli/model.py: info, check, fk, ik, dynamics, urdf, srdf,
mjcf, show): outputs against closed_form, exit codes, --force, overridden URDFs against the closed
form with the same overrides, the viewer in chromium."""

import dataclasses
import json
import os
import shutil
import signal
import subprocess
import sys
import time
import urllib.request
import uuid
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from helpers import CONFIG, HELD, RAISED, REPORT, dark, frame_pose, patch, render
from phantom_pin import closed_form as cf
from phantom_pin import describe
from phantom_pin.config import MODELS, read
from phantom_pin.config.sampling import random_states

CONFIG_DIR, URDF_PATH = MODELS["premium_1_5"].config, MODELS["premium_1_5"].urdf


def test_check_passes_and_reports_every_method(cli):
    code, out, _ = cli("check", "-n", "200", "--json")
    report = json.loads(out)
    assert code == 0 and report["passed"] and len(report["checks"]) == 8


def test_fk_and_ik_agree_with_the_closed_form(cli):
    theta = [0.2, 0.3, 0.4]
    code, out, _ = cli("fk", *map(str, theta), "--json")
    assert code == 0
    np.testing.assert_allclose(json.loads(out)["g_st"], cf.forward_kinematics(theta, REPORT), atol=1e-12)
    position = cf.forward_kinematics(theta, REPORT)[:3, 3]
    code, out, _ = cli("ik", *(str(float(x)) for x in position), "--json")
    np.testing.assert_allclose(json.loads(out)["theta"], theta, atol=1e-9)


def test_dynamics_agrees_with_the_closed_form(cli):
    code, out, _ = cli("dynamics", "--theta", "0.1", "0.2", "0.3", "--dtheta", "1", "2", "3",
                       "--ddtheta", "0", "1", "0", "--json")
    data = json.loads(out)
    np.testing.assert_allclose(data["tau"], cf.inverse_dynamics([0.1, 0.2, 0.3], [1, 2, 3], [0, 1, 0], REPORT),
                               rtol=1e-9)
    np.testing.assert_allclose(data["M"], cf.mass_matrix([0.1, 0.2, 0.3], REPORT), rtol=1e-9)


def test_info_lists_the_report_masses(cli):
    code, out, _ = cli("info", "--json")
    masses = {link["name"]: link["mass"] for link in json.loads(out)["links"]}
    # each hinge pin's mass is taken from its neighbour: together they are the report's segment
    masses["crank_link"] += masses.pop("crank_pin_link")
    masses["lower_bar_link"] += masses.pop("forearm_pin_link")
    assert masses == pytest.approx({"turret_link": 0.35, "upper_arm_link": 0.2359, "crank_link": 0.1906,
                                    "lower_bar_link": 0.0249, "forearm_link": 0.0202}, rel=1e-15)


def test_coupled_stops_without_a_posture_exit_2_and_write_nothing(tmp_path, cli):
    """`check` looped for ever on them; the MJCF was written with an inverted tendon range."""
    config = tmp_path / "config"
    shutil.copytree(CONFIG_DIR, config)
    limits = config / "joint_limits.yaml"
    limits.write_text(limits.read_text().replace("theta2_minus_theta3_max: 1.1344640137963142",
                                                 "theta2_minus_theta3_max: -1.0"))
    for argv in (["check", "-n", "10"], ["mjcf", "-o", str(tmp_path / "phantom.xml")]):
        code, _, err = cli("--config", str(config), *argv)
        assert code == 2 and "stops.theta2_minus_theta3_max" in err and err.count("\n") == 1
    code, _, err = cli("mjcf", "-o", str(tmp_path / "phantom.xml"),
                       "--set", "stops.theta3_minus_theta2_max=-1.2")
    assert code == 2 and "after the overrides" in err and err.count("\n") == 1
    assert not (tmp_path / "phantom.xml").exists()


def test_urdf_refuses_to_overwrite_without_force(tmp_path, cli):
    target = tmp_path / "phantom.urdf"
    assert cli("urdf", "--output", str(target))[0] == 0
    assert target.read_text() == URDF_PATH.read_text()
    target.write_text("keep me")
    code, _, err = cli("urdf", "--output", str(target))
    assert code == 2 and "--force" in err and target.read_text() == "keep me"
    assert cli("urdf", "--output", str(target), "--force", "--prefix", "r_")[0] == 0
    assert 'name="r_joint1"' in target.read_text()


def test_urdf_overrides_reach_kinematics_dynamics_and_mimic_tags(tmp_path, cli):
    params = tmp_path / "params.yaml"
    params.write_text("segment_a: {mass: 0.03}\nsegment_be.inertia.xx: 12.0e-4\n")
    target = tmp_path / "phantom.urdf"
    code, _, _ = cli("urdf", "-o", str(target), "--params", str(params), "--set", "l1=0.2096")
    assert code == 0
    model = pin.buildModelFromUrdf(str(target), mimic=True)
    expected = dataclasses.replace(REPORT, l1=0.2096, ma=0.03, Ibexx=12.0e-4)
    rotors = np.diag(CONFIG.actuation.armature)  # the report's inertias include them; the URDF
                                                 # leaves them to the SRDF, not loaded here
    data = model.createData()
    for theta in np.random.default_rng(7).uniform(CONFIG.limits.lower, CONFIG.limits.upper, (50, 3)):
        pin.framesForwardKinematics(model, data, theta)
        g = data.oMf[model.getFrameId("report_s")].actInv(data.oMf[model.getFrameId("tip")])
        np.testing.assert_allclose(g.homogeneous, cf.forward_kinematics(theta, expected), atol=1e-12)
        mass = pin.crba(model, data, theta)
        mass = np.triu(mass) + np.triu(mass, 1).T
        np.testing.assert_allclose(mass + rotors, cf.mass_matrix(theta, expected), rtol=1e-9, atol=1e-15)
    assert target.read_text().count("<mimic ") == 4


def test_srdf_override_of_the_rotor_inertia_reaches_the_armature(tmp_path, cli):
    """The SRDF carries the rotor inertia; the whole configuration is checked, so 2e-6 kg m^2
    (which leaves upper_arm_link's inertia non-physical) writes no SRDF either."""
    target = tmp_path / "phantom.srdf"
    assert cli("srdf", "-o", str(target), "--set", "actuation.motor.rotor_inertia=1.1e-6")[0] == 0
    model = pin.buildModelFromUrdf(str(URDF_PATH), mimic=True)
    pin.loadRotorParameters(model, str(target), False)
    np.testing.assert_allclose(model.armature, [1.1e-6 * r**2 for r in CONFIG.actuation.ratios],
                               rtol=1e-12)
    code, _, err = cli("srdf", "-o", str(tmp_path / "bad.srdf"), "--set", "actuation.motor.rotor_inertia=2e-6")
    assert code == 2 and "upper_arm_link" in err and not (tmp_path / "bad.srdf").exists()


@pytest.mark.chromium
def test_show_html_puts_the_tip_where_the_overridden_kinematics_say(tmp_path, cli):
    """--config with l1 = 0.25: the tip ball is drawn where that model (not the
    shipped one) puts it; an existing file is kept without --force."""
    config = tmp_path / "config"
    shutil.copytree(CONFIG_DIR, config)
    kinematics = config / "kinematics.yaml"
    kinematics.write_text(kinematics.read_text().replace("l1: 0.215 ", "l1: 0.25 "))
    html = tmp_path / "scene.html"
    argv = ["--config", str(config), "show", "--html", str(html), "--theta", *map(str, RAISED)]
    assert cli(*argv)[0] == 0
    image = render(html, tmp_path / "scene.png")
    tips = [frame_pose(pin.buildModelFromXML(urdf, mimic=True), RAISED, "tip").translation
            for urdf in (describe(config).urdf, URDF_PATH.read_text())]
    assert np.linalg.norm(tips[0] - tips[1]) > 0.03
    assert dark(patch(image, tips[0])) and not dark(patch(image, tips[1]))
    code, _, err = cli(*argv)
    assert code == 2 and "--force" in err


def _server_child(pid: int) -> int | None:
    """The pid of process ``pid``'s meshcat server child (viewer/server.py), from /proc, or None."""
    for path in Path("/proc").glob("[0-9]*/stat"):
        try:
            parent = int(path.read_text().rsplit(")", 1)[1].split()[1])
            if parent == pid and b"server.py" in (path.parent / "cmdline").read_bytes():
                return int(path.parent.name)
        except (OSError, ValueError, IndexError):   # a process that ended meanwhile
            continue
    return None


def _holding(token: str) -> set[int]:
    """The pids of the processes whose environment holds ``token`` (a command's and its
    children's: they inherit it), from /proc."""
    found = set()
    for path in Path("/proc").glob("[0-9]*/environ"):
        try:
            if token.encode() in path.read_bytes():
                found.add(int(path.parent.name))
        except OSError:                  # a process that ended meanwhile
            continue
    return found


def _none_left(token: str, within: float = 10.0) -> bool:
    """True once no process holds ``token`` (zombies count as gone: their environment is empty)."""
    deadline = time.monotonic() + within
    while _holding(token):
        if time.monotonic() > deadline:
            return False
        time.sleep(0.05)
    return True


@pytest.mark.parametrize("stop, parent_ignores_sigint", [
    (signal.SIGINT, False), (signal.SIGINT, True), (signal.SIGTERM, True)])
def test_show_serves_on_loopback_until_interrupted(stop, parent_ignores_sigint):
    """Ctrl-C or SIGTERM stops `show` and its server, also when the parent started it with
    SIGINT ignored (as background jobs and some CI shells do: Python then ignores SIGINT).
    Whatever happens, the command's whole session is killed at the end: nothing leaks. The server
    is its child process (read from /proc), gone once it exited: another worker's server may take
    the port it served on, so the port is not what is checked."""
    def ignore_sigint():
        signal.signal(signal.SIGINT, signal.SIG_IGN)

    token = f"PHANTOM_PIN_TEST={uuid.uuid4()}"
    process = subprocess.Popen([sys.executable, "-m", "phantom_pin.cli", "show"], stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True, start_new_session=True,
                               env={**os.environ, "PHANTOM_PIN_TEST": token.split("=")[1]},
                               preexec_fn=ignore_sigint if parent_ignores_sigint else None)
    try:
        line = process.stdout.readline()
        url = line.split(" at ")[1].split()[0]
        assert url.startswith("http://127.0.0.1:")
        with urllib.request.urlopen(url, timeout=10) as response:
            assert response.status == 200
        server = _server_child(process.pid)
        assert server is not None and server in _holding(token)    # how the test below finds it
        process.send_signal(stop)
        assert process.wait(30) == 0
    finally:
        if process.poll() is None:  # never leak the command or its server (same session)
            os.killpg(process.pid, signal.SIGKILL)
            process.wait()
        process.stdout.close()
        process.stderr.close()
    assert _none_left(token)  # the server went with the command


@pytest.mark.slow
@pytest.mark.parametrize("stop", [signal.SIGINT, signal.SIGTERM])
def test_show_stops_the_same_way_on_a_signal_right_after_the_url(stop):
    """The signal sent the moment the URL line arrives, twice: `show` exits 0 and takes its
    server with it every time (before: the handler came after the URL, so a SIGINT in between
    ended it with 130, 1 run in 3 under load). No process of the command's (its environment's
    token, which its server inherits: test_show_serves_on_loopback_until_interrupted checks that)
    is left once it exited."""
    for _ in range(2):
        token = f"PHANTOM_PIN_TEST={uuid.uuid4()}"
        process = subprocess.Popen([sys.executable, "-m", "phantom_pin.cli", "show"], stdout=subprocess.PIPE,
                                   stderr=subprocess.PIPE, text=True, start_new_session=True,
                                   env={**os.environ, "PHANTOM_PIN_TEST": token.split("=")[1]})
        try:
            line = process.stdout.readline()
            process.send_signal(stop)
            assert line.split(" at ")[1].startswith("http://127.0.0.1:"), line
            assert process.wait(30) == 0, process.stderr.read()
        finally:
            if process.poll() is None:
                os.killpg(process.pid, signal.SIGKILL)
                process.wait()
            process.stdout.close()
            process.stderr.close()
        assert _none_left(token)


def _config(tmp_path, file, old, new):
    config = tmp_path / "config"
    shutil.copytree(CONFIG_DIR, config)
    path = config / file
    assert old in path.read_text()
    path.write_text(path.read_text().replace(old, new, 1))
    return config


def test_check_of_a_custom_configuration_passes_and_skips_the_appendix(tmp_path, cli):
    """The example l1 = 0.2096 of docs/models.md: Phantom vs closed form with the same parameters
    passes; the appendix's torques are not the numbers of this arm, so their row is n/a."""
    config = _config(tmp_path, "kinematics.yaml", "l1: 0.215 ", "l1: 0.2096 ")
    code, out, _ = cli("--config", str(config), "check", "-n", "300", "--json")
    report = json.loads(out)
    assert code == 0 and report["passed"] and len(report["checks"]) == 8
    assert report["checks"][-1]["max_error"] is None
    assert all(row["max_error"] < 1e-9 for row in report["checks"][:-1])
    code, out, _ = cli("--config", str(config), "check", "-n", "30")
    assert code == 0 and "n/a" in out and "all checks pass" in out


def test_check_draws_and_evaluates_in_chunks(monkeypatch, cli):
    """250 states in chunks of 7: 35 chunks of 7 and one of 5, every check passes."""
    sizes = []

    def spy(limits, n, seed):
        sizes.append(n)
        return random_states(limits, n, seed)
    monkeypatch.setattr("phantom_pin.dynamics.verification.CHUNK", 7)
    monkeypatch.setattr("phantom_pin.dynamics.verification.random_states", spy)
    report = json.loads(cli("check", "-n", "250", "--json")[1])
    assert sizes == [7] * 35 + [5] and report["passed"] and report["states"] == 250


@pytest.mark.parametrize("file, old, new, message", [
    ("joint_limits.yaml", "joint2: {lower: -1.4660765716752369, upper: 2.076941809873252}",
     "joint2: {lower: -100.0, upper: 100.0}",
     "joint2.lower must be within one turn"),
    ("actuation.yaml", "motor:", "motor: [", "not valid YAML at line"),
    ("physical_parameters.yaml", "segment_a:", "segment_a: {", "not valid YAML at line"),
])
def test_bad_configuration_gives_one_line_naming_the_file(tmp_path, cli, file, old, new, message):
    config = _config(tmp_path, file, old, new)
    for argv in (["check", "-n", "10"], ["urdf", "-o", str(tmp_path / "x.urdf")]):
        code, _, err = cli("--config", str(config), *argv)
        assert code == 2 and message in err and file in err and err.count("\n") == 1
    assert not (tmp_path / "x.urdf").exists()


@pytest.mark.parametrize("argv, warned", [
    (["fk", "0", "0", "3.5"], "theta [0 0 3.5] rad is outside the joint limits"),
    (["dynamics", "--theta", "1.6", "0", "0"], "theta [1.6 0 0] rad is outside the joint limits"),
    # 0.3 m straight below the shoulder (0, l2, -l1): theta3 = -44.6 deg < -29 deg
    (["ik", "0", "-0.13", "-0.215"], "the solution theta"),
    (["fk", "1.5707963267948966", "2.076941809873252", "3.036872898470133"], None),  # on the limits: inside
    (["ik", "0", "0.12", "0.05"], None),
])
def test_out_of_limit_angles_are_computed_with_one_warning_line(cli, argv, warned):
    code, out, err = cli(*argv)
    assert code == 0 and out
    if warned is None:
        assert err == ""
    else:
        assert err.count("\n") == 1 and err.startswith("phantom-pin: warning: ") and warned in err


def test_mjcf_scene_includes_the_model_from_its_own_folder(tmp_path, cli, monkeypatch):
    """-o sub/m.xml --scene s.xml: the scene includes sub/m.xml, and MuJoCo loads it; the scene
    may not be the model's own file."""
    import mujoco

    monkeypatch.chdir(tmp_path)
    (tmp_path / "sub").mkdir()
    code, _, _ = cli("mjcf", "-o", "sub/m.xml", "--scene", "s.xml")
    assert code == 0 and '<include file="sub/m.xml"' in (tmp_path / "s.xml").read_text()
    assert mujoco.MjModel.from_xml_path(str(tmp_path / "s.xml")).njnt == 7
    code, _, err = cli("mjcf", "-o", "m.xml", "--scene", "m.xml")
    assert code == 2 and err.count("\n") == 1 and "--scene: m.xml is the --output file" in err
    assert not (tmp_path / "m.xml").exists()


def test_info_aligns_every_link_name(cli):
    code, out, _ = cli("info")
    rows = [line for line in out.splitlines() if line.split(" ")[0].endswith("_link") and "[" in line]
    assert code == 0 and len(rows) == 7 and len({row.index("[") for row in rows}) == 1


def test_check_refuses_more_states_than_a_few_minutes_take(cli):
    code, out, err = cli("check", "-n", "100000000000")
    assert code == 2 and out == "" and err == ("phantom-pin: error: -n: 100000000000 states is more than 2e+07 "
                                               "(about 4 minutes); check fewer\n")


def test_info_says_when_overrides_apply(tmp_path, capsys):
    """A review found `info --params id.yaml` printing `model premium_1_5` as for the shipped
    model: the first line counts the overridden numbers (JSON: ``overrides``), and the joints'
    numbers are the overlay's."""
    from phantom_pin.cli import main

    overlay = tmp_path / "id.yaml"
    overlay.write_text("l1: 0.2\nactuation.friction.coulomb: 0.02\n")
    assert main(["info", "--params", str(overlay)]) == 0
    assert capsys.readouterr().out.splitlines()[0] == "model premium_1_5, with 2 overridden number(s) (--params/--set)"
    assert main(["info", "--params", str(overlay), "--set", "l2=0.21", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["overrides"] == 3 and data["device"]["friction"]["coulomb"] == [0.02] * 3
    assert main(["info", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["overrides"] == 0


# -- show on the Touch, pipes, errors naming their option, outputs staged, --prefix, --gimbal -----
TOUCH = read("touch")


def bounds(lower, upper):
    """The warning's "[a b c]..[d e f]" of limits (rad), as warn_limits prints them."""
    return "[" + " ".join(f"{v:.6g}" for v in lower) + "]..[" + " ".join(f"{v:.6g}" for v in upper) + "]"


def test_show_on_the_touch_checks_the_arm_and_the_gimbal_against_their_own_ranges(tmp_path, cli):
    """`show` on the Touch (six joints) checks the arm's angles against the arm's stops and
    the gimbal's against the gimbal's range: inside both, no warning; beyond either, one warning
    line naming it and its bounds. The ranges are the configuration's."""
    arm, gimbal = TOUCH.limits, TOUCH.gimbal
    inside = (np.array(arm.lower) + np.array(arm.upper)) / 2
    code, out, err = cli("--model", "touch", "show", "--theta", *map(str, inside),
                         "--gimbal", "0.1", "0.2", "0.3", "--html", str(tmp_path / "in.html"))
    assert code == 0 and err == "" and out.startswith("wrote") and (tmp_path / "in.html").is_file(), err
    beyond = [0.0, 0.0, gimbal.upper[2] + 0.01]  # joint6 just past its stop
    code, out, err = cli("--model", "touch", "show", "--theta", *map(str, inside),
                         "--gimbal", *map(str, beyond), "--html", str(tmp_path / "gimbal.html"))
    assert code == 0 and err.count("\n") == 1, err
    assert "warning: gimbal" in err and bounds(gimbal.lower, gimbal.upper) in err, err
    above = [0.0, 0.0, arm.upper[2] + 0.01]
    code, out, err = cli("--model", "touch", "show", "--theta", *map(str, above),
                         "--html", str(tmp_path / "arm.html"))
    assert code == 0 and err.count("\n") == 1, err
    assert "warning: theta" in err and bounds(arm.lower, arm.upper) in err, err


@pytest.mark.parametrize("prefix, valid", [('a"b', False), ("a b", False), ("9lives", False), ("arm/", True),
                                           ("left_", True), ("", True)])
def test_urdf_refuses_a_prefix_that_is_no_ros_name(tmp_path, cli, prefix, valid):
    """urdf/srdf --prefix takes only what a ROS name can start with (ROS 2's rule for names:
    tokens of letters, digits and _, not starting with a digit, separated by /; codegen's --prefix
    checks its own): anything else (a space, a quote, a leading digit) is refused in one line
    naming --prefix, nothing written."""
    code, out, err = cli("srdf", "-o", str(tmp_path / "p.srdf"), "--prefix", prefix)
    assert code == (0 if valid else 2) and (tmp_path / "p.srdf").exists() == valid
    if not valid:
        assert err == ("phantom-pin: error: --prefix: expected a ROS name's start (letters, digits, _ and /, not "
                       f"starting with a digit), got {prefix!r}\n")


def test_fk_and_dynamics_take_gimbal_angles(cli, six):
    """fk --gimbal prints the stylus frame's and its tip's poses and dynamics --gimbal holds the
    gimbal there: against the six-joint model built here (1e-12)."""
    theta, dtheta, ddtheta = [0.1, 0.3, 0.5], [0.4, -1.0, 2.0], [3.0, -2.0, 1.0]
    code, out, err = cli("--model", "touch", "fk", *theta, "--gimbal", *HELD, "--json")
    assert (code, err) == (0, "")
    poses = json.loads(out)
    for key, frame in (("stylus", "stylus"), ("stylus_tip", "stylus_tip"), ("g_st", "tip")):
        np.testing.assert_allclose(poses[key], six.pose(theta, HELD, frame), rtol=0, atol=1e-12)
    code, out, err = cli("--model", "touch", "dynamics", "--theta", *theta, "--dtheta", *dtheta, "--ddtheta",
                         *ddtheta, "--gimbal", *HELD, "--json")
    assert (code, err) == (0, "")
    results = json.loads(out)
    torques = six.torques(np.array(theta), HELD, np.array(dtheta), np.array(ddtheta))
    np.testing.assert_allclose(results["tau"], torques, rtol=0, atol=1e-12 * np.abs(torques).max())
    np.testing.assert_allclose(results["M"], six.mass(theta, HELD), rtol=0, atol=1e-15)
    np.testing.assert_allclose(results["N"], six.torques(np.array(theta), HELD, np.zeros(3), np.zeros(3)), rtol=0,
                               atol=1e-14)


@pytest.mark.parametrize("command", [["fk", "0", "0", "0"], ["dynamics", "--theta", "0", "0", "0"],
                                     ["simulate", "--theta0", "0", "0.3", "0.4", "--duration", "0.01"]])
def test_gimbal_angles_for_a_model_without_a_gimbal_are_refused_naming_the_option(cli, command):
    """fk, dynamics and simulate refuse --gimbal for a model without a stylus gimbal, in one
    line naming the option and the model."""
    code, out, err = cli(*command, "--gimbal", "0.1", "0.2", "0.3")
    assert (code, out) == (2, "") and err.startswith("phantom-pin: error: --gimbal: the model 'premium_1_5' has no "
                                                     "stylus gimbal"), err
