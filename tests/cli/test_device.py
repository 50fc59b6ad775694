"""phantom-pin simulate and the device data of phantom-pin info (cli/device.py): outputs against
phantom_pin.simulate and the published numbers, exit codes, --force, nothing written on failure,
the format from the output file's extension."""

import csv
import json

import numpy as np
import pytest
import yaml

from helpers import HELD, REPORT, recorded_trajectory
from phantom_pin import closed_form, config, simulate
from phantom_pin.cli import main

START = ["0.3", "0.8", "0.4"]


def test_simulate_json_is_the_python_result(tmp_path, cli):
    target = tmp_path / "run.json"
    code, out, _ = cli("simulate", "--theta0", *START, "--dtheta0", "0", "1", "0", "--duration", "0.05",
                       "--rate", "500", "--quantization", "-o", str(target))
    assert code == 0 and "26 samples" in out
    data = json.loads(target.read_text())
    expected = simulate([0.3, 0.8, 0.4], 0.05, dtheta0=[0, 1, 0], rate=500.0, quantization=True)
    for name in ("t", "theta", "dtheta", "tau", "tau_commanded", "current", "tip"):
        np.testing.assert_array_equal(data[name], getattr(expected, name))
    assert data["units"]["theta"] == "rad" and data["settings"]["substeps"] == expected.substeps
    assert data["settings"]["saturation"] == "continuous"        # the policy applied (before: null)


def test_simulate_csv_on_stdout_with_gravity_compensation_holds_still(cli):
    code, out, _ = cli("simulate", "--theta0", *START, "--duration", "0.02", "--controller", "gravity",
                       "--format", "csv")
    rows = list(csv.reader(out.splitlines()))
    assert rows.pop(1) == ["# phantom-pin: model premium_1_5", " convention report"]  # L12's record, a comment
    assert code == 0 and rows[0][:4] == ["t [s]", "theta1 [rad]", "theta2 [rad]", "theta3 [rad]"] and len(rows) == 22
    table = np.array(rows[1:], dtype=float)
    np.testing.assert_allclose(table[:, 1:4], np.tile([0.3, 0.8, 0.4], (21, 1)), atol=1e-12)
    np.testing.assert_allclose(table[:, 8:10], np.tile(closed_form.gravity([0.3, 0.8, 0.4], REPORT)[1:], (21, 1)),
                               rtol=1e-9)
    assert rows[0][-3:] == ["tip_x [m]", "tip_y [m]", "tip_z [m]"]


def test_simulate_keeps_files_and_writes_nothing_on_failure(tmp_path, cli):
    target = tmp_path / "run.csv"
    code, _, err = cli("simulate", "--theta0", *START, "--duration", "-1", "-o", str(target))
    assert code == 2 and "duration" in err and err.count("\n") == 1 and not target.exists()
    target.write_text("keep")
    code, _, err = cli("simulate", "--theta0", *START, "--duration", "0.01", "-o", str(target))
    assert code == 2 and "--force" in err and target.read_text() == "keep"
    code, _, _ = cli("simulate", "--theta0", *START, "--duration", "0.01", "-o", str(target), "--force",
                     "--format", "csv", "--no-friction", "--no-hard-stops", "--no-saturation")
    assert code == 0 and target.read_text().startswith("t [s],")


@pytest.mark.parametrize("argv, message", [
    (["--theta0", "0", "nan", "0", "--duration", "1"], "error: --theta0: contains NaN"),
    (["--theta0", *START, "--duration", "1", "--rate", "0"], "error: --rate: expected a finite number > 0"),
    (["--theta0", *START, "--duration", "10000", "--rate", "0.001"], "error: --duration: 10000 s at 0.001 Hz needs"),
    (["--theta0", *START, "--duration", "1", "--controller", "pd"], "invalid choice"),
    (["--theta0", *START], "required: --duration"),
    (["--duration", "1"], "required: --theta0"),
    (["--theta0", *START, "--duration", "1", "--no-saturation", "--saturation", "peak"], "not allowed with"),
    (["--theta0", *START, "--duration", "1", "-o", ""], "error: --output: empty; give a file name"),
    (["--theta0", *START, "--duration", "1", "-o", ".", "--force"], "error: --output: . is a folder"),
    (["--theta0", *START, "--duration", "1", "-o", "missing/x.json"], "error: --output: folder missing does not"),
    (["--trajectory", "t.csv", "--rate", "500"], "error: --rate: --trajectory sets it"),
    (["--trajectory", "t.csv", "--dtheta0", "0", "0", "0"], "error: --dtheta0: --trajectory sets it"),
])
def test_simulate_bad_arguments_give_one_line_and_exit_code_2(cli, argv, message):
    code, _, err = cli("simulate", *argv)
    assert code == 2 and message in err and err.count("\n") == 1


def test_info_lists_the_device_data_with_sources(cli):
    code, out, _ = cli("info", "--json")
    device = json.loads(out)["device"]
    assert code == 0 and set(device) == {"stops", "friction", "motor", "encoder", "transmission_ratio"}
    assert all(section["source"] for section in device.values())
    assert device["motor"]["stall_torque"] == 0.129 and device["motor"]["torque_constant"] == 0.0234
    np.testing.assert_allclose(device["encoder"]["resolution"], 2 * np.pi / (4096 * np.array([13.3, 11.6, 11.6])))
    np.testing.assert_allclose(device["stops"]["upper"], np.radians([90, 119, 214]))
    code, out, _ = cli("info")
    assert "theta3 - theta2 <= 55.0" in out and "118743" in out and "HEDM-5500" in out


def test_simulate_warns_once_when_it_starts_inside_a_stop(capsys):
    assert main(["simulate", "--theta0", "3", "0", "0", "--duration", "0.01"]) == 0
    err = capsys.readouterr().err
    assert err == "phantom-pin: warning: --theta0 [3.0, 0.0, 0.0] rad starts beyond the stops, which push it back\n"
    assert main(["simulate", "--theta0", "3", "0", "0", "--duration", "0.01", "--no-hard-stops"]) == 0
    assert capsys.readouterr().err == ""                            # no stops, no warning (before: the same)


def _trajectory(path, degrees=(), milliseconds=False, openhaptics=False):
    """A smooth 3 s trajectory inside the stops at 1 kHz with its exact derivatives and the
    report model's torque (N m), written as excite writes it; optionally with a unit slip."""
    from phantom_pin import Phantom
    from phantom_pin.identification.data import io
    from phantom_pin.interfaces import conventions

    t = np.arange(3001) / 1000.0
    w = 2 * np.pi / 3.0
    centre, amplitude = np.array([0.0, 0.5, 0.4]), np.array([0.3, 0.2, 0.2])
    theta = centre + amplitude * np.sin(w * t)[:, None] * (1 - np.cos(w * t))[:, None] / 2
    # derivatives of a sin(wt)(1 - cos(wt))/2 = a (sin(wt) - sin(2wt)/2) / 2
    dtheta = amplitude * (w * np.cos(w * t) - w * np.cos(2 * w * t))[:, None] / 2
    ddtheta = amplitude * (-w**2 * np.sin(w * t) + 2 * w**2 * np.sin(2 * w * t))[:, None] / 2
    tau = Phantom().inverse_dynamics(theta, dtheta, ddtheta)
    if openhaptics:
        theta, dtheta, ddtheta = (conventions.openhaptics_from_theta(x) for x in (theta, dtheta, ddtheta))
        tau = conventions.openhaptics_torque_from_tau(tau)
    columns = {"theta": theta, "dtheta": dtheta, "ddtheta": ddtheta}
    for name in degrees:
        columns[name] = np.degrees(columns[name])
    io.write_csv(path, io.TRAJECTORY_COLUMNS, np.column_stack(
        [t * 1000 if milliseconds else t, columns["theta"], columns["dtheta"], columns["ddtheta"], tau]))
    return path


@pytest.mark.parametrize("slip, message", [
    ({"degrees": ("theta",)}, "rate of change of theta is 57.3 times dtheta (1 expected): the columns disagree; "
                              "are the angles in degrees?"),
    ({"milliseconds": True}, "rate of change of theta is 0.001 times dtheta (1 expected): the columns disagree; "
                             "is t in ms?"),
    ({"degrees": ("dtheta",)}, "the rate of change of theta is 0.01745 times dtheta"),
    ({"degrees": ("theta", "dtheta", "ddtheta")}, "--trajectory: TRAJ: its first state: "),
])
def test_simulate_names_the_trajectory_file_for_its_unit_slips(tmp_path, cli, slip, message):
    """Before: a trajectory in degrees was blamed on --theta0 (not given), one in ms on --duration."""
    traj = _trajectory(tmp_path / "traj.csv", **slip)
    code, out, err = cli("simulate", "--trajectory", str(traj), "-o", str(tmp_path / "log.csv"))
    assert code == 2 and out == "" and err.count("\n") == 1 and message.replace("TRAJ", str(traj)) in err, err
    assert not (tmp_path / "log.csv").exists()


def test_simulate_tracks_a_consistent_trajectory_and_warns_when_openhaptics_is_read_as_the_report(tmp_path,
                                                                                                  cli):
    """The same trajectory in the report's units tracks without a warning; in OpenHaptics' mN m
    read as N m (no --convention) nearly every command saturates: a warning line that says so,
    its share equal to the clipped samples of the written log (tau differs from tau_commanded)."""
    traj, log = _trajectory(tmp_path / "traj.csv"), tmp_path / "log.csv"
    code, _, err = cli("simulate", "--trajectory", str(traj), "-o", str(log))
    assert code == 0 and err == ""
    traj = _trajectory(tmp_path / "oh.csv", openhaptics=True)
    code, _, err = cli("simulate", "--trajectory", str(traj), "-o", str(log), "--force")
    data = np.loadtxt(log, delimiter=",", skiprows=1)
    share = 100 * np.mean(np.any(data[:, 7:10] != data[:, 10:13], axis=1))
    assert code == 0 and share > 50 and err == (
        f"phantom-pin: warning: {share:.1f} % of the commanded torques exceeded the saturation and were clipped "
        "(is the file in OpenHaptics' mN m? --convention openhaptics)\n")
    code, _, err = cli("simulate", "--trajectory", str(traj), "-o", str(log), "--force",
                       "--convention", "openhaptics")
    assert code == 0 and err == ""


@pytest.mark.parametrize("argv, message", [
    (["--duration", "1e308"], "--duration: 1e+308 s at 1000 Hz gives more than 1000000 samples"),
    (["--duration", "1e200", "--rate", "1e200"], "--duration: 1e+200 s at 1e+200 Hz gives more than 1000000 samples"),
    (["--duration", "10", "--rate", "1", "--set", "actuation.friction.viscous=1e6"],
     "error: the model (--model, --config, --params, --set): 10 s at 1 Hz needs"),
    (["--duration", "0.5", "--set", "segment_a.mass=1e3"],
     "error: the model (--model, --config, --params, --set): with at most 0 N m applied and 0 rad/s at the start, "
     "the device itself diverged"),
])
def test_simulate_blames_what_is_at_fault_in_one_line(tmp_path, cli, argv, message):
    """Before: OverflowError tracebacks for 1e308 s; a stiff friction blamed on --rate; a
    1000 kg segment blamed on "controller or dtheta0" (both zero)."""
    code, out, err = cli("simulate", "--theta0", "0.1", "0.3", "0.4", *argv, "-o", str(tmp_path / "r.csv"))
    assert code == 2 and out == "" and err.count("\n") == 1 and message in err, err
    assert not (tmp_path / "r.csv").exists()


# -- info's sources, simulate --gimbal, the model and convention recorded in the files ------------


def test_info_says_which_numbers_of_a_sourced_section_the_overrides_changed(tmp_path, cli):
    """info gives each sourced section's source as its file states it (read here with PyYAML),
    and for a section whose numbers an override changed, says which ones are not from it
    (OVERRIDDEN here, then the rest's source); the others are unchanged, in --json and the text."""
    folder = config.MODELS["touch"].config
    stated = {**yaml.safe_load((folder / "actuation.yaml").read_text())["sources"],
              **yaml.safe_load((folder / "joint_limits.yaml").read_text())["sources"],
              **yaml.safe_load((folder / "gimbal.yaml").read_text())["sources"]}
    overlay = tmp_path / "overlay.yaml"
    overlay.write_text("actuation:\n  friction:\n    viscous:\n      joint2: 0.01\ntip_offset: 0.04\n")
    code, out, err = cli("--model", "touch", "info", "--json", "--params", str(overlay),
                         "--set", "joint_torque_limit.joint1=0.5")
    assert code == 0 and err == ""
    data = json.loads(out)["device"]
    expected = {"friction": "friction.viscous.joint2", "motor": "joint_torque_limit.joint1"}
    for section in ("stops", "friction", "motor", "encoder", "transmission_ratio"):
        changed = expected.get(section)
        assert data[section]["source"] == (stated[section] if changed is None else
                                           f"OVERRIDDEN here: {changed} (not from the source); the rest: "
                                           f"{stated[section]}")
    code, out, _ = cli("--model", "touch", "info", "--params", str(overlay))
    assert f"  source: OVERRIDDEN here: tip_offset (not from the source); the rest: {stated['gimbal']}\n" in out
    assert f"  source: {stated['friction']}\n" not in out


def test_simulate_with_the_gimbal_held_and_its_gravity_compensated_stays_at_rest(cli):
    """simulate --gimbal holds the gimbal there in the plant as in the controller: the arm under
    `--controller gravity` (gravity(theta, gimbal), the six-joint model's rows) stays at rest when
    the plant holds the gimbal there too (the arm locked at those angles, a second computation):
    within 1e-12 rad over 0.5 s, without friction or stops. Held at locked_at instead, the
    stylus's load at HELD is missing and the arm moves."""
    theta0 = [0.2, 0.3, 0.5]
    common = ("--model", "touch", "simulate", "--theta0", *theta0, "--duration", "0.5", "--controller", "gravity",
              "--no-friction", "--no-hard-stops")
    code, out, err = cli(*common, "--gimbal", *HELD)
    assert (code, err) == (0, "")
    result = json.loads(out)
    assert result["settings"]["gimbal"] == HELD.tolist()
    assert np.abs(np.array(result["theta"]) - theta0).max() < 1e-12
    with pytest.MonkeyPatch.context() as patch:  # the plant at locked_at, the controller at HELD
        patch.setattr("phantom_pin.device.simulation.held", lambda description, gimbal: description)
        moved = json.loads(cli(*common, "--gimbal", *HELD)[1])
    assert np.abs(np.array(moved["theta"]) - theta0).max() > 1e-3


def test_excite_and_simulate_record_the_model_and_the_convention(tmp_path, cli):
    """excite's trajectory and simulate's log name the model and the convention of their columns
    on their second line (a # comment, which the readers and numpy.loadtxt skip); simulate's log
    is in the report's convention whatever its input's."""
    code, _, err = cli("--model", "touch", "excite", "-o", tmp_path / "t.csv", "--duration", "5", "--iterations", "1",
                       "--restarts", "1", "--convention", "openhaptics", "-q")
    assert (code, err) == (0, "")
    lines = (tmp_path / "t.csv").read_text().splitlines()
    assert lines[0].startswith("t,theta1,") and lines[1] == "# phantom-pin: model touch, convention openhaptics"
    assert np.loadtxt(tmp_path / "t.csv", delimiter=",", skiprows=1).shape == (5001, 13)
    code, _, err = cli("--model", "touch", "simulate", "--trajectory", tmp_path / "t.csv", "--convention",
                       "openhaptics", "-o", tmp_path / "log.csv", "-q")
    assert (code, err) == (0, "")
    assert (tmp_path / "log.csv").read_text().splitlines()[1] == "# phantom-pin: model touch, convention report"


@pytest.mark.parametrize("given, written", [(("--model", "touch"), ("premium_1_5", "report")),
                                            (("--model", "touch", "--convention", "openhaptics"), ("touch", "report")),
                                            ((), ("touch", "report"))])
def test_a_trajectory_for_another_model_or_convention_is_refused_naming_both(tmp_path, cli, given, written):
    """simulate refuses a trajectory recorded for another model or convention than the ones
    given, before the run, in one line naming both, nothing written."""
    path = recorded_trajectory(tmp_path / "t.csv", f"# phantom-pin: model {written[0]}, convention {written[1]}")
    code, out, err = cli("simulate", "--trajectory", path, "-o", tmp_path / "log.csv", *given)
    model = "touch" if "touch" in given else "premium_1_5"
    convention = "openhaptics" if "openhaptics" in given else "report"
    assert (code, out) == (2, "") and err == (
        f"phantom-pin: error: --trajectory: {path} was written for the model {written[0]} in the {written[1]} "
        f"convention, read here for the model {model} in the {convention} convention (give --model and "
        "--convention as written, or delete its '# phantom-pin' line)\n")
    assert not (tmp_path / "log.csv").exists()


@pytest.mark.parametrize("record", [None, "# phantom-pin: model touch, convention report", "# a comment of one's own"])
def test_a_trajectory_without_the_record_or_with_the_right_one_is_read(tmp_path, cli, record):
    """A trajectory without the record (files before 0.5.0, other tools) is read as before, and
    so is one with the matching record: the run tracks the trajectory (its start is the file's
    first state)."""
    path = recorded_trajectory(tmp_path / "t.csv", record)
    code, out, err = cli("--model", "touch", "simulate", "--trajectory", path, "--format", "json", "-q")
    assert (code, err) == (0, "")
    np.testing.assert_allclose(json.loads(out)["theta"][0], [0.0, 0.3, 0.5], rtol=0, atol=1e-15)


def test_a_malformed_record_is_refused(tmp_path, cli):
    """A '# phantom-pin' line of another form than 'model NAME, convention NAME' is refused in
    one line quoting it."""
    path = recorded_trajectory(tmp_path / "t.csv", "# phantom-pin: touch, report")
    code, _, err = cli("--model", "touch", "simulate", "--trajectory", path)
    assert code == 2 and err == (f"phantom-pin: error: --trajectory: {path}: its line '# phantom-pin: touch, report' "
                                 "is not '# phantom-pin: model NAME, convention NAME'\n")


@pytest.mark.parametrize("name, kind", [("run.csv", "csv"), ("run.json", "json"), ("RUN.CSV", "csv")])
def test_simulate_writes_the_format_of_the_extension(tmp_path, cli, name, kind):
    """Before: `simulate ... -o run.csv` wrote JSON into run.csv."""
    target = tmp_path / name
    code, _, _ = cli("simulate", "--theta0", "0.1", "0.3", "0.4", "--duration", "0.01", "-o", str(target))
    text = target.read_text()
    assert code == 0
    if kind == "csv":
        rows = list(csv.reader(line for line in text.splitlines() if not line.startswith("#")))   # the record
        assert rows[0][0] == "t [s]" and len(rows) == 12 and float(rows[-1][0]) == pytest.approx(0.01, abs=1e-15)
    else:
        assert len(json.loads(text)["t"]) == 11


@pytest.mark.parametrize("argv, message", [
    (["-o", "OUT/run.csv", "--format", "json"], "--format: json into"),
    (["-o", "OUT/run.json", "--format", "csv"], "--format: csv into"),
    (["-o", "OUT/run.txt"], "--output: "),
    (["-o", ""], "--output: empty"),
])
def test_simulate_refuses_a_format_that_contradicts_the_extension_before_the_run(tmp_path, cli, argv, message):
    args = [a.replace("OUT", str(tmp_path)) for a in argv]
    code, out, err = cli("simulate", "--theta0", "0.1", "0.3", "0.4", "--duration", "1e9", *args)
    assert code == 2 and out == "" and err.count("\n") == 1 and message in err, err   # 1e9 s: not run
    assert list(tmp_path.iterdir()) == []


def test_simulate_format_without_a_file_and_with_a_matching_extension(tmp_path, cli):
    code, out, _ = cli("simulate", "--theta0", "0.1", "0.3", "0.4", "--duration", "0.01", "--format", "csv")
    assert code == 0 and out.startswith("t [s],")
    target = tmp_path / "run.txt"
    code, _, _ = cli("simulate", "--theta0", "0.1", "0.3", "0.4", "--duration", "0.01", "--format", "json",
                     "-o", str(target))
    assert code == 0 and len(json.loads(target.read_text())["t"]) == 11
