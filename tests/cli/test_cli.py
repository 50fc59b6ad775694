"""The phantom-pin command line: outputs against closed_form, exit codes, --force,
overridden URDFs against the closed form with the same overrides, the viewer in chromium."""

import dataclasses
import json
import os
import shutil
import signal
import stat
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


@pytest.mark.parametrize("argv, message", [
    (["ik", "0", "0.3", "0.3"], "outside the reachable shell"),
    (["fk", "0", "0"], "required"),
    (["fk", "0", "nan", "0"], "theta: contains NaN"),
    (["check", "-n", "0"], "-n"),
    (["bogus"], "invalid choice"),
])
def test_bad_arguments_give_one_line_and_exit_code_2(cli, argv, message):
    code, _, err = cli(*argv)
    assert code == 2 and message in err and err.count("\n") == 1


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


@pytest.mark.parametrize("argv, message", [
    (["--set", "foo=1"], "foo: no parameter file has the key 'foo'"),
    (["--set", "motor.max_speed=1"], "qualify it, e.g. actuation.motor.max_speed"),
    (["--set", "kinematics.l4=1"], "kinematics.yaml has no key 'l4'"),
    (["--set", "l1=abc"], "--set: expected KEY=NUMBER"),
    (["--set", "segment_a=1"], "segment_a: not a number"),
    (["--set", "l1=-0.1"], "l1 must be positive"),
    (["--params", "/nonexistent/params.yaml"], "--params"),
])
def test_bad_overrides_give_one_line_and_exit_code_2(tmp_path, cli, argv, message):
    target = tmp_path / "phantom.urdf"
    code, _, err = cli("urdf", "-o", str(target), *argv)
    assert code == 2 and message in err and err.count("\n") == 1 and not target.exists()


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


@pytest.mark.parametrize("argv, message", [
    (["urdf", "-o", "/nonexistent_dir/x.urdf"], "--output: folder /nonexistent_dir does not exist"),
    (["urdf", "-o", "{tmp}", "--force"], "is a folder"),
    (["srdf", "-o", "{tmp}", "--force"], "is a folder"),
    (["show", "--html", "{tmp}", "--force"], "--html: "),
    (["dynamics", "--theta", "0", "0", "0", "--dtheta", "1e200", "1e200", "1e200", "--json"], "overflows"),
    (["check", "-n", "1.5"], "-n: expected a positive whole number"),
    (["ik", "0", "0.17", "0.17", "--branch", "left"], "invalid choice"),
])
def test_more_bad_arguments_give_one_line_and_exit_code_2(tmp_path, cli, argv, message):
    code, out, err = cli(*(a.format(tmp=tmp_path) for a in argv))
    assert code == 2 and message in err and err.count("\n") == 1 and out == ""


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


def test_binary_params_file_is_named(tmp_path, cli):
    params = tmp_path / "params.yaml"
    params.write_bytes(bytes(range(128, 256)))
    code, _, err = cli("urdf", "-o", str(tmp_path / "x.urdf"), "--params", str(params))
    assert code == 2 and "params.yaml: not a text file" in err and err.count("\n") == 1


def test_negative_numbers_in_scientific_notation_are_values(cli):
    code, out, _ = cli("fk", "-1e-3", "0", "0", "--json")
    assert code == 0
    np.testing.assert_allclose(json.loads(out)["g_st"], cf.forward_kinematics([-1e-3, 0, 0], REPORT), atol=1e-12)
    code, out, _ = cli("dynamics", "--theta", "-1e-3", "0.1", "0.2", "--dtheta", "-2E+0", "0", "-.5",
                       "--json")
    assert code == 0
    np.testing.assert_allclose(json.loads(out)["tau"], cf.inverse_dynamics([-1e-3, 0.1, 0.2], [-2, 0, -0.5],
                                                                           [0, 0, 0], REPORT), rtol=1e-9)


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


def _popen(*argv):
    return subprocess.Popen([sys.executable, "-m", "phantom_pin.cli", *argv],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def test_closed_output_pipe_ends_quietly():
    """phantom-pin info | head -1: the reader goes away; no traceback, exit 141 (128 + SIGPIPE)."""
    process = _popen("info")
    process.stdout.close()
    assert process.wait(60) == 141
    assert process.stderr.read() == ""


def _cpu_seconds(pid: int) -> float:
    fields = open(f"/proc/{pid}/stat").read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def _peak_rss_mb(pid: int) -> float:
    status = open(f"/proc/{pid}/status").read()
    return int(status.split("VmHWM:")[1].split()[0]) / 1024


@pytest.mark.slow
def test_huge_check_runs_in_bounded_memory_and_ctrl_c_gives_one_line():
    """check -n 2e7, the most it takes (2 TiB of states at once before, for 1e11): after 3 s of
    CPU (its start, about 0.6 s, then a dozen of its 10 000-state chunks, about 0.18 s each; its
    2e7 states' angles alone are 480 MB) its peak memory is below 400 MB; Ctrl-C then ends it
    with one line and exit 130 (128 + SIGINT). The command starts with SIGINT's default
    disposition, whatever pytest's own (a pytest started in the background ignores SIGINT, its
    children inherit that, and Python then leaves SIGINT ignored: check ran on, as any program
    whose parent ignores SIGINT does)."""
    process = subprocess.Popen([sys.executable, "-m", "phantom_pin.cli", "check", "-n", "20000000"],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                               preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    try:
        deadline = time.monotonic() + 120
        while _cpu_seconds(process.pid) < 3.0 and process.poll() is None and time.monotonic() < deadline:
            time.sleep(0.2)
        assert process.poll() is None, process.stderr.read()
        assert _peak_rss_mb(process.pid) < 400
        process.send_signal(signal.SIGINT)
        assert process.wait(60) == 130
    finally:
        process.kill()
    assert process.stderr.read() == "phantom-pin: interrupted\n"


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


def test_every_command_takes_the_overrides(cli, tmp_path):
    """--set and --params reach every command's model: fk with l1, l2 changed follows eq. 10
    with them (written here); info reports the changed mass; check passes on the changed model."""
    params = tmp_path / "p.yaml"
    params.write_text("l1: 0.2\nsegment_a.mass: 0.03\n")
    code, out, _ = cli("fk", "0.3", "0.5", "0.7", "--params", str(params), "--set", "l2=0.15", "--json")
    tip = np.array(json.loads(out)["g_st"])[:3, 3]
    l1, l2, (t1, t2, t3) = 0.2, 0.15, (0.3, 0.5, 0.7)
    reach = l1 * np.cos(t2) + l2 * np.sin(t3)
    np.testing.assert_allclose(tip, [np.sin(t1) * reach, l2 - l2 * np.cos(t3) + l1 * np.sin(t2),
                                     -l1 + np.cos(t1) * reach], rtol=0, atol=1e-12)
    code, out, _ = cli("info", "--params", str(params), "--json")
    masses = {link["name"]: link["mass"] for link in json.loads(out)["links"]}
    assert code == 0 and masses["forearm_link"] == pytest.approx(0.03, rel=1e-12)
    code, out, _ = cli("check", "-n", "50", "--set", "l1=0.2")
    assert code == 0 and "all checks pass" in out
    code, _, err = cli("dynamics", "--theta", "0", "0", "0", "--set", "foo=1")
    assert code == 2 and err.count("\n") == 1 and "foo" in err


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


@pytest.mark.parametrize("unbuffered", ["1", None])
def test_simulate_into_a_pipe_closed_part_way_exits_141(unbuffered):
    """Output into a pipe that its reader closes part way exits 141, without a word, buffered or
    with PYTHONUNBUFFERED=1 (as Docker images set it: unbuffered, Python writes the 219 kB at once
    and the reader's exit leaves a short write, not an error); docs/cli.md says 141. Read in full,
    the output is a whole JSON document of duration x rate + 1 samples."""
    import os
    import subprocess
    import sys

    env = {k: v for k, v in os.environ.items() if k != "PYTHONUNBUFFERED"} | (
        {"PYTHONUNBUFFERED": unbuffered} if unbuffered else {})
    argv = [sys.executable, "-m", "phantom_pin.cli", "simulate", "--theta0", "0", "0.3", "0.4", "--duration", "1"]
    process = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env)
    assert len(process.stdout.read(10)) == 10
    process.stdout.close()
    assert process.wait(120) == 141 and process.stderr.read() == b""
    process.stderr.close()
    whole = subprocess.run(argv, capture_output=True, env=env, check=True, timeout=120)
    assert len(whole.stdout) > 2**16 and len(json.loads(whole.stdout)["t"]) == 1001


@pytest.mark.parametrize("argv, message", [
    (["ik", "1e308", "0", "0"], "position: [1.e+308 0.e+000 0.e+000] m is 1e+308 m from the shoulder, outside the "
                                "reachable shell [0.0450, 0.3850] m"),                       # 4 digits, not 309
    (["--set", "=0.2", "fk", "0", "0", "0"], "--set: expected KEY=NUMBER, got '=0.2' (no key)"),       # no key
    (["urdf", "-o", "/dev/full", "-f"], "--output: cannot write /dev/full (No space left on device)"),  # a failed write
    (["--config", "{tmp}", "info"], "{tmp}: not a configuration folder (it has none of kinematics.yaml, "),  # empty
    (["excite", "-o", "{tmp}/old.csv"], "--output: {tmp}/old.csv exists; use --force to overwrite it"),  # one wording
    (["urdf", "-o", "{tmp}/old.csv"], "--output: {tmp}/old.csv exists; use --force to overwrite it"),
])
def test_an_error_names_the_option_at_fault_in_one_readable_line(tmp_path, cli, argv, message):
    """An error names the option at fault in one readable line (exit 2, nothing overwritten): ik's
    distance to the shoulder in four significant digits (not 309 digits at 1e308), --set without
    a key as such, a write that fails by --output, a folder with none of the parameter files as
    not a configuration folder, an existing output with "use --force" in every command."""
    (tmp_path / "old.csv").write_text("kept\n")
    code, out, err = cli(*[a.replace("{tmp}", str(tmp_path)) for a in argv])
    assert (code, out) == (2, "") and err.count("\n") == 1
    assert err.startswith("phantom-pin: error: " + message.replace("{tmp}", str(tmp_path))), err
    assert (tmp_path / "old.csv").read_text() == "kept\n"


@pytest.mark.parametrize("argv, option", [(["identify", "{missing}", "-o", "{tmp}/id.yaml"], "LOG"),
                                          (["simulate", "--trajectory", "{missing}"], "--trajectory")])
def test_a_missing_log_or_trajectory_is_named_by_its_option(tmp_path, cli, argv, option):
    """A log or trajectory that cannot be read is named by its option (LOG, --trajectory) with the
    system's reason, in one line (not Python's errno text)."""
    missing = tmp_path / "missing.csv"
    code, out, err = cli(*[a.replace("{missing}", str(missing)).replace("{tmp}", str(tmp_path)) for a in argv])
    assert (code, out) == (2, "") and err == f"phantom-pin: error: {option}: {missing}: cannot read (No such file or " \
                                             "directory)\n"


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


@pytest.mark.parametrize("output, scene", [("model.xml", "/dev/full"), ("/dev/full", "scene.xml")])
def test_mjcf_writes_neither_file_when_one_cannot_be_written(tmp_path, cli, output, scene):
    """mjcf writes both of its files or neither: with either unwritable (a full device), the
    folder stays empty and one line names the option whose file failed."""
    paths = [p if p.startswith("/dev") else str(tmp_path / p) for p in (output, scene)]
    code, out, err = cli("mjcf", "-o", paths[0], "--scene", paths[1], "--force")
    option = "--scene" if scene.startswith("/dev") else "--output"
    assert (code, out, err) == (2, "", f"phantom-pin: error: {option}: cannot write /dev/full (No space left on "
                                       "device)\n")
    assert list(tmp_path.iterdir()) == []


def test_written_files_take_the_umask_and_an_overwritten_file_keeps_its_mode(tmp_path, cli):
    """The command line's files are staged beside their targets and renamed into place: a new
    file gets the mode open() would give it (0666 less the umask), an overwritten one keeps its
    own, a symbolic link is written through (as open() would), and no temporary file is left
    behind."""
    mask = os.umask(0o027)
    try:
        assert cli("mjcf", "-o", tmp_path / "m.xml", "--scene", tmp_path / "s.xml")[0] == 0
        os.chmod(tmp_path / "s.xml", 0o600)
        (tmp_path / "s.xml").write_text("old\n")
        assert cli("mjcf", "-o", tmp_path / "m.xml", "--scene", tmp_path / "s.xml", "--force")[0] == 0
    finally:
        os.umask(mask)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.xml", "s.xml"]
    assert stat.S_IMODE((tmp_path / "m.xml").stat().st_mode) == 0o640
    assert stat.S_IMODE((tmp_path / "s.xml").stat().st_mode) == 0o600
    assert "m.xml" in (tmp_path / "s.xml").read_text()
    (tmp_path / "link.xml").symlink_to(tmp_path / "m.xml")  # written through, as open() would
    (tmp_path / "m.xml").write_text("old\n")
    assert cli("mjcf", "-o", tmp_path / "link.xml", "--force")[0] == 0
    assert (tmp_path / "link.xml").is_symlink() and "<mujoco" in (tmp_path / "m.xml").read_text()


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
