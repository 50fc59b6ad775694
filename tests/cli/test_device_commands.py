"""phantom-pin simulate and the device data of phantom-pin info: outputs against
phantom_pin.simulate and the published numbers, exit codes, --force, nothing written on failure."""

import csv
import json

import numpy as np
import pytest

from helpers import REPORT
from phantom_pin import closed_form, simulate
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
    from phantom_pin import Phantom, drivers
    from phantom_pin.identification import io

    t = np.arange(3001) / 1000.0
    w = 2 * np.pi / 3.0
    centre, amplitude = np.array([0.0, 0.5, 0.4]), np.array([0.3, 0.2, 0.2])
    theta = centre + amplitude * np.sin(w * t)[:, None] * (1 - np.cos(w * t))[:, None] / 2
    # derivatives of a sin(wt)(1 - cos(wt))/2 = a (sin(wt) - sin(2wt)/2) / 2
    dtheta = amplitude * (w * np.cos(w * t) - w * np.cos(2 * w * t))[:, None] / 2
    ddtheta = amplitude * (-w**2 * np.sin(w * t) + 2 * w**2 * np.sin(2 * w * t))[:, None] / 2
    tau = Phantom().inverse_dynamics(theta, dtheta, ddtheta)
    if openhaptics:
        theta, dtheta, ddtheta = (drivers.openhaptics_from_theta(x) for x in (theta, dtheta, ddtheta))
        tau = drivers.openhaptics_torque_from_tau(tau)
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
