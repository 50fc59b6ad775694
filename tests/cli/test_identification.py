"""phantom-pin excite and identify: the trajectory stays inside the stops and the torque
limits, and malformed logs exit 2 with one line and write nothing."""

import numpy as np
import pytest
import yaml

from helpers import CONFIG, CONFIG_DIR, REPORT, T10, model_torques, recorded_trajectory, sines
from phantom_pin import Phantom, closed_form, describe
from phantom_pin.cli import main
from phantom_pin.identification.data import io
from phantom_pin.identification.fitting.excitation import continuous_effort

DESCRIPTION = describe()
EFFORT = continuous_effort(DESCRIPTION)   # N m at the joints


def test_excite_stays_inside_the_stops_and_torque_limits(tmp_path, cli):
    path = tmp_path / "traj.csv"
    code, out, _ = cli("excite", "-o", path, "--duration", "5", "--rate", "200",
                       "--iterations", "5", "--restarts", "1")
    assert code == 0 and "condition number" in out
    table = np.loadtxt(path, delimiter=",", skiprows=1)
    assert np.loadtxt(path, delimiter=",", max_rows=1, dtype=str).tolist() == list(io.TRAJECTORY_COLUMNS)
    theta = table[:, 1:4]
    # the coupled stops of the issue (65 and 55 deg) and the joint box, with excite's 0.05 rad
    # margin and 80 % torque share at every row of the file (before: only at the optimiser's
    # 150 points per period, and the file reached 0.0435 rad and 83.7 %)
    assert (theta[:, 1] - theta[:, 2] <= np.deg2rad(65) - 0.05 + 1e-9).all()
    assert (theta[:, 2] - theta[:, 1] <= np.deg2rad(55) - 0.05 + 1e-9).all()
    lower, upper = box()
    assert (theta >= lower + 0.05 - 1e-9).all() and (theta <= upper - 0.05 + 1e-9).all()
    assert (np.abs(table[:, 10:13]) <= 0.8 * EFFORT + 1e-12).all()
    np.testing.assert_allclose(table[[0, -1], 4:10], 0, atol=1e-12)    # at rest at both ends
    np.testing.assert_allclose(np.diff(table[:, 0]), 1 / 200, rtol=1e-9)
    # the velocities are the positions' derivatives
    np.testing.assert_allclose(np.gradient(table[:, 1:4], 1 / 200, axis=0)[1:-1], table[1:-1, 4:7],
                               atol=2e-3 * np.abs(table[:, 4:7]).max())
    code, _, err = cli("excite", "-o", path)
    assert code == 2 and "exists" in err


def box():
    """The URDF's joint box intersected with the stops' box, read from joint_limits.yaml."""
    data = yaml.safe_load((CONFIG_DIR / "joint_limits.yaml").read_text())
    joints = ("joint1", "joint2", "joint3")
    lower = [max(data[j]["lower"], data["stops"][j]["lower"]) for j in joints]
    upper = [min(data[j]["upper"], data["stops"][j]["upper"]) for j in joints]
    return np.array(lower), np.array(upper)


def test_limits_are_the_box_and_the_coupled_stops():
    """Limits.slack: upper bounds of (theta1, theta2, theta3, theta2 - theta3), then lower ones."""
    limits = CONFIG.limits
    lower, upper = box()
    np.testing.assert_array_equal(limits.slack(lower)[:3], upper - lower)
    np.testing.assert_array_equal(limits.slack(upper)[4:7], upper - lower)
    at_stops = np.array([[0.0, 0.9, 0.9 - np.deg2rad(65)], [0.0, 0.0, np.deg2rad(55)]])
    slack = limits.slack(at_stops)
    np.testing.assert_allclose([slack[0, 3], slack[1, 7]], 0, atol=1e-15)
    from phantom_pin.config.sampling import sample_postures
    assert (limits.slack(sample_postures(limits, 500, np.random.default_rng(3))) >= 0).all()


def write(path, header, rows):
    path.write_text(header + "\n" + "\n".join(",".join(str(v) for v in row) for row in rows) + "\n")


def good_rows(n=3000, rate=1000.0):
    t = np.arange(n) / rate
    theta = 0.2 * np.sin(np.outer(t, [1.0, 1.3, 1.7]))
    return np.column_stack([t, theta, 0.01 * theta])


@pytest.mark.parametrize("case, message", [
    ("missing", "missing column(s) tau3"),
    ("nan", "NaN or inf on line"),
    ("time", "time is not strictly increasing"),
    ("short", "too short"),
    ("rate", "not at a fixed rate"),
    ("text", "not a number"),
    ("flat", "too little motion: joint(s) 2, 3 move faster than"),
])
def test_malformed_logs_exit_2_with_one_line(tmp_path, cli, case, message):
    header, rows = "t,theta1,theta2,theta3,tau1,tau2,tau3", good_rows()
    if case == "missing":
        header, rows = "t,theta1,theta2,theta3,tau1,tau2", rows[:, :6]
    elif case == "nan":
        rows[10, 2] = np.nan
    elif case == "time":
        rows[100, 0] = rows[99, 0]
    elif case == "short":
        rows = rows[:1000]
    elif case == "flat":   # only joint 1 moves: gravity and the parallelogram are not excited
        rows[:, 2:4] = 0.3
    elif case == "rate":
        rows[500:, 0] += 0.0005
    log = tmp_path / "log.csv"
    write(log, header, rows)
    if case == "text":
        log.write_text(log.read_text().replace("0.001,", "abc,", 1))
    out = tmp_path / "id.yaml"
    code, _, err = cli("identify", log, "-o", out)
    assert code == 2 and message in err and err.count("\n") == 1, err
    assert not out.exists()


def test_identify_refuses_to_overwrite(tmp_path, cli):
    out = tmp_path / "id.yaml"
    out.write_text("keep")
    code, _, err = cli("identify", tmp_path / "missing.csv", "-o", out)
    assert code == 2 and "exists" in err and out.read_text() == "keep"


def test_excitation_respects_a_tight_torque_limit():
    """With 20 % of the continuous torque allowed the constraint is active; the torques,
    computed independently (closed form + the friction law), stay below it between the
    optimiser's samples too (2 % slack)."""
    from phantom_pin.identification.fitting import excitation
    from phantom_pin.report import closed_form

    result = excitation.optimise(Phantom(DESCRIPTION), torque_share=0.2, iterations=10, restarts=1)
    t = np.linspace(0, result.trajectory.period, 2001)
    theta, dtheta, ddtheta = result.trajectory(t)
    tau = closed_form.inverse_dynamics(theta, dtheta, ddtheta, REPORT) + 5e-4 * dtheta + 0.01 * np.sign(dtheta)
    share = np.abs(tau).max(axis=0) / EFFORT
    assert share.max() <= 0.2 * 1.02 and share.max() >= 0.15, share


def test_excite_writes_whole_periods_and_consistent_columns(tmp_path, cli):
    """--duration 7 --period 5 rounds up to two whole periods (10 s); over the whole file the
    accelerations are the rates' derivatives (central differences) and the torques are the
    report's inverse dynamics (closed form) plus the configuration's friction law, written out
    here: viscous dtheta + coulomb sign(dtheta)."""
    path = tmp_path / "traj.csv"
    code, _, _ = cli("excite", "-o", path, "--duration", "7", "--period", "5", "--rate", "500",
                     "--iterations", "3", "--restarts", "1")
    assert code == 0
    table = np.loadtxt(path, delimiter=",", skiprows=1)
    t, theta, dtheta, ddtheta, tau = table[:, 0], table[:, 1:4], table[:, 4:7], table[:, 7:10], table[:, 10:13]
    assert t[-1] == pytest.approx(10.0, abs=1e-12) and len(t) == 5001
    derivative = np.gradient(dtheta, t, axis=0)[1:-1]
    np.testing.assert_allclose(ddtheta[1:-1], derivative, rtol=0, atol=2e-3 * np.abs(ddtheta).max())
    friction = CONFIG.actuation.friction
    expected = (closed_form.inverse_dynamics(theta, dtheta, ddtheta, REPORT) + np.asarray(friction.viscous) * dtheta
                + np.asarray(friction.coulomb) * np.sign(dtheta))
    np.testing.assert_allclose(tau, expected, rtol=0, atol=1e-12 * np.abs(expected).max() + 1e-15)


@pytest.mark.parametrize("option, message", [
    (["--duration", "inf"], "--duration: expected a finite positive number"),
    (["--rate", "inf"], "--rate: expected a finite positive number"),
    (["--period", "nan"], "--period: expected a finite positive number"),
    (["--rate", "1e9"], "--duration, --rate: 20 s at 1e+09 Hz is more than 2000000 rows"),
    (["--duration", "1e300"], "--duration, --rate: 1e+300 s at 1000 Hz is more than 2000000 rows"),
    (["--period", "1e-300"], "--period: 1e-300 s is outside 0.5..600 s"),
    (["--rate", "1"], "--rate: 1 Hz samples the highest harmonic (5 / 5 s) fewer than 20 times per cycle"),
    (["-o", "/nonexistent-folder/traj.csv"], "--output: folder /nonexistent-folder does not exist"),
])
def test_excite_checks_its_options_before_any_work(tmp_path, cli, option, message):
    """One line, exit 2, nothing written, within a second: before the optimisation."""
    import time

    path = tmp_path / "traj.csv"
    start = time.monotonic()
    output = [] if option[0] == "-o" else ["-o", path]      # -o given once (twice is refused)
    code, out, err = cli("excite", *output, *option)
    assert time.monotonic() - start < 1.0
    assert code == 2 and err.count("\n") == 1 and message in err, err
    assert not path.exists() and list(tmp_path.iterdir()) == []


def test_excite_writes_at_least_one_period(tmp_path, cli):
    path = tmp_path / "traj.csv"
    code, _, _ = cli("excite", "-o", path, "--duration", "1e-9", "--rate", "100", "--iterations", "2",
                     "--restarts", "1")
    t = np.loadtxt(path, delimiter=",", skiprows=1)[:, 0]
    assert code == 0 and len(t) == 501 and t[-1] == pytest.approx(5.0)


def test_the_excitation_holds_its_bounds_at_every_written_sample():
    """optimise() samples a period at 12 points only here; between them its optimum leaves the
    stops by 1.2 rad. Checked at the 5000 samples the file will hold, the returned trajectory
    keeps the 0.05 rad margin and the 80 % torque share at every one of them."""
    from phantom_pin.identification.fitting import excitation
    from phantom_pin.identification.structure import constants

    times = np.arange(5000) / 1000.0
    result = excitation.optimise(Phantom(DESCRIPTION), 5.0, 5, samples=12, iterations=40, restarts=1, seed=3,
                                 times=times)
    states = result.trajectory(times)
    torque = constants.regressor(*states, DESCRIPTION) @ constants.nominal(DESCRIPTION)
    assert CONFIG.limits.slack(states[0]).min() >= 0.05 - 1e-9
    assert (np.abs(torque) <= 0.8 * EFFORT + 1e-12).all()
    assert result.min_slack == pytest.approx(CONFIG.limits.slack(states[0]).min(), abs=1e-12)


def test_excite_simulate_identify_without_code(tmp_path, cli):
    """excite -> simulate --trajectory (feed-forward plus PD on the shipped device: Pinocchio,
    rotors, friction, stops, saturation) -> identify (the general structure): the written
    overlay's mass matrix and gravity are the report's closed form within 0.5 % of their
    largest entries at 200 postures, and its friction the shipped law's within 1 %."""
    from phantom_pin import closed_form
    from phantom_pin.config import read_overrides
    from phantom_pin.config.sampling import sample_postures

    traj, log, overlay = tmp_path / "traj.csv", tmp_path / "log.csv", tmp_path / "id.yaml"
    assert cli("excite", "-o", traj, "--duration", "10", "--iterations", "15", "--restarts", "1")[0] == 0
    assert cli("simulate", "--trajectory", traj, "--format", "csv", "-o", log)[0] == 0
    assert cli("identify", log, "-o", overlay)[0] == 0
    keys = read_overrides(overlay)
    identified = Phantom(describe(overrides=keys))
    theta = sample_postures(CONFIG.limits, 200, np.random.default_rng(4), draws=800)
    mass, gravity = closed_form.mass_matrix(theta, CONFIG.report), closed_form.gravity(theta, CONFIG.report)
    assert np.abs(identified.mass_matrix(theta) - mass).max() < 5e-3 * np.abs(mass).max()
    assert np.abs(identified.gravity(theta) - gravity).max() < 5e-3 * np.abs(gravity).max()
    law = CONFIG.actuation.friction
    for j in range(3):      # each joint's own law, written per joint
        assert keys[f"actuation.friction.viscous.joint{j + 1}"] == pytest.approx(law.viscous[j], rel=1e-2)
        assert keys[f"actuation.friction.coulomb.joint{j + 1}"] == pytest.approx(law.coulomb[j], rel=1e-2)
    code, _, err = cli("simulate", "--trajectory", traj, "--duration", "3")
    assert code == 2 and "--duration: --trajectory sets it" in err
    # the overlay carries its model and lengths: another model refuses it (before, the CAD
    # model's overlay applied to premium_1_5 silently took the 1.5's lengths)
    assert keys["model"] == "premium_1_5" and (keys["l1"], keys["l2"], keys["l3"]) == (
        CONFIG.kinematics.l1, CONFIG.kinematics.l2, CONFIG.kinematics.l3)
    urdf = tmp_path / "touch.urdf"
    code, out, err = cli("--model", "touch", "urdf", "--params", overlay, "-o", urdf)
    assert code == 2 and out == "" and err.count("\n") == 1 and not urdf.exists()
    assert "model: these overrides were made for the model 'premium_1_5'" in err and "--model premium_1_5" in err


@pytest.mark.parametrize("arguments, message", [
    (["identify", "LOG", "-o", "OUT/missing/id.yaml"], "missing does not exist"),
    (["identify", "LOG", "-o", "OUT", "--force"], "is a folder; name a file"),
    (["identify", "LOG", "-o", "OUT/id.yaml", "--cutoff", "1e-9"], "--cutoff: 1e-09 Hz is too low for a"),
    (["identify", "LOG", "-o", "OUT/id.yaml", "--cutoff", "nan"], "--cutoff: expected a finite positive"),
    (["excite", "-o", "OUT/traj.csv", "--seed", "-1"], "--seed: expected an integer of at least 0"),
    (["excite", "-o", "OUT/traj.csv", "--iterations", "0"], "--iterations: expected an integer of at least 1"),
    (["excite", "-o", "OUT", "--force"], "is a folder; name a file"),
])
def test_bad_options_name_themselves_before_any_work(tmp_path, cli, arguments, message):
    """What a review tried: one line naming the option, exit 2, nothing written, and no fit or
    optimisation run first (before: a missing folder failed after the whole fit)."""
    path = tmp_path / "log.csv"
    io.write_log(path, *(lambda t: (t, np.zeros((len(t), 3)) + t[:, None], np.zeros((len(t), 3))))(
        np.arange(3001) / 1000.0))
    before = sorted(p.name for p in tmp_path.iterdir())
    args = [a.replace("LOG", str(path)).replace("OUT", str(tmp_path)) for a in arguments]
    code, out, err = cli(*args)
    assert code == 2 and err.count("\n") == 1 and message in err, err
    assert out == "" and sorted(p.name for p in tmp_path.iterdir()) == before


@pytest.mark.parametrize("command", ["excite", "identify LOG"])
def test_a_folder_one_cannot_write_in_is_refused_before_any_work(tmp_path, cli, monkeypatch, command):
    """The one output check of every writer (validation.output_path, which the command line's
    output() calls) asks the folder's permission before any work: --output names the folder.
    (os.access is stubbed: root may write anywhere.)"""
    monkeypatch.setattr("phantom_pin._validation.os.access", lambda *_: False)
    args = [str(tmp_path / "log.csv") if a == "LOG" else a for a in command.split()]
    code, out, err = cli(*args, "-o", str(tmp_path / "out.yaml" if "identify" in args else tmp_path / "out.csv"))
    assert code == 2 and f"--output: cannot write in {tmp_path}" in err and out == "", err
    assert list(tmp_path.iterdir()) == []


# -- outputs, warnings, and logs refused before any fit ---------------------------------------------


@pytest.mark.parametrize("command, name, kind", [
    (["excite"], "t.json", "CSV; name a .csv file"),
    (["identify", "LOG"], "id.json", "a YAML overlay; name a .yaml or .yml file"),
])
def test_excite_and_identify_refuse_an_output_of_another_format(tmp_path, cli, command, name, kind):
    """excite writes CSV and identify a YAML overlay: an --output named for another format is
    refused in one line naming the format to give, nothing written."""
    (tmp_path / "log.csv").write_text("t,theta1,theta2,theta3,tau1,tau2,tau3\n")
    target = tmp_path / name
    argv = [a.replace("LOG", str(tmp_path / "log.csv")) for a in command]
    code, out, err = cli(*argv, "-o", str(target))
    assert (code, out) == (2, "") and err == f"phantom-pin: error: --output: {target}: this command writes {kind}\n"
    assert not target.exists()


def test_excite_says_when_it_rounds_the_duration_up_to_whole_periods(tmp_path, cli):
    """excite writes whole periods: a --duration that is none is rounded up with one warning line
    stating the length written, which the file's own time column is; a whole number of periods
    is written as given, without a word."""
    path = tmp_path / "t.csv"
    code, out, err = cli("excite", "-o", str(path), "--duration", "3", "--rate", "100",
                         "--iterations", "2", "--restarts", "1")
    assert code == 0 and err == ("phantom-pin: warning: --duration 3 s rounded up to 1 whole period(s) of 5 s: 5 s "
                                 "(the excitation is periodic; --period sets its length)\n")
    assert np.loadtxt(path, delimiter=",", skiprows=1)[-1, 0] == pytest.approx(5.0, abs=1e-12)
    code, out, err = cli("excite", "-o", str(path), "--duration", "10", "--rate", "100", "--force",
                         "--iterations", "2", "--restarts", "1")
    assert code == 0 and err == "" and np.loadtxt(path, delimiter=",", skiprows=1)[-1, 0] == pytest.approx(10.0)


@pytest.mark.parametrize("second", ["tau1", "TAU1 [mN m]"])
def test_a_log_naming_one_column_twice_is_refused(tmp_path, cli, second):
    """A log whose header names one column twice (in any case, with a unit or not) is refused in
    one line naming the column and how often, nothing written: either could be the one meant
    (another unit, a filtered copy)."""
    t = np.arange(3001) / 1000.0
    theta = 0.2 * np.sin(np.outer(t, [1.0, 1.3, 1.7]))
    table = np.column_stack([t, theta, 0.01 * theta, 10 * theta[:, 0]])
    log = tmp_path / "log.csv"
    np.savetxt(log, table, delimiter=",", header=f"t,theta1,theta2,theta3,tau1,tau2,tau3,{second}", comments="")
    code, out, err = cli("identify", str(log), "-o", str(tmp_path / "id.yaml"))
    assert (code, out) == (2, "") and err == (f"phantom-pin: error: {log}: the header names tau1 2 times; name each "
                                              "column once\n"), err
    assert not (tmp_path / "id.yaml").exists()


def _log(path, units):
    t = np.arange(3001) / 1000.0
    theta = 0.2 * np.sin(np.outer(t, [1.0, 1.3, 1.7]))
    header = "t [s]," + ",".join(f"theta{j} [rad]" for j in (1, 2, 3)) + "," + ",".join(
        f"tau{j} [{units}]" for j in (1, 2, 3))
    np.savetxt(path, np.column_stack([t, theta, 10 * theta]), delimiter=",", header=header, comments="")


def test_a_log_whose_header_says_another_torque_unit_is_refused_before_any_fit(tmp_path, cli):
    """A log whose header gives the torques in another unit than the convention's is refused at
    once (under 1 s, before any fit) in one line naming the column, the unit and --convention,
    nothing written; the units each convention takes are read (the report's N m in any spelling,
    OpenHaptics' mN m)."""
    import time

    from phantom_pin.identification.data import io

    for units, convention in (("N m", "report"), ("Nm", "report"), ("N*m", "report"), ("mN m", "openhaptics")):
        _log(tmp_path / "ok.csv", units)
        assert io.read_log(tmp_path / "ok.csv", convention).tau.shape == (3001, 3)
    _log(tmp_path / "log.csv", "mN m")
    start = time.monotonic()
    code, out, err = cli("identify", str(tmp_path / "log.csv"), "-o", str(tmp_path / "id.yaml"))
    assert time.monotonic() - start < 1.0
    assert (code, out) == (2, "") and err == (
        f"phantom-pin: error: {tmp_path / 'log.csv'}: tau1 is in mN m (its header), the report convention's torques "
        "in N m: give the convention of the log (--convention; OpenHaptics': mN m) or convert it\n")
    assert not (tmp_path / "id.yaml").exists()
    _log(tmp_path / "log.csv", "N m")
    with pytest.raises(io.LogError, match="tau1 is in N m .its header., the openhaptics convention's torques in mN m"):
        io.read_log(tmp_path / "log.csv", "openhaptics")


def test_identify_passes_min_speed_to_the_fit(tmp_path, monkeypatch):
    """identify hands --min-speed to the fit (a spy in place of estimate)."""
    from phantom_pin import Phantom
    from phantom_pin.identification.data import io
    from phantom_pin.identification.verdict import result

    phantom = Phantom()
    theta, dtheta, ddtheta = sines(T10)
    io.write_log(tmp_path / "log.csv", T10, theta, model_torques(phantom, theta, dtheta, ddtheta))
    seen = {}

    def spy(*args, **kwargs):
        seen.update(kwargs)
        raise io.LogError("stopped by the test")

    monkeypatch.setattr(result, "estimate", spy)
    assert main(["identify", str(tmp_path / "log.csv"), "-o", str(tmp_path / "id.yaml"), "--min-speed", "0.05"]) == 2
    assert seen["min_speed"] == 0.05


def test_identify_accept_warns_on_stderr(tmp_path, cli):
    """identify --accept prints its warnings on stderr, as every command does, the results alone
    on stdout. The model's own torques with tau3 2.5 times too small: a gain outside 0.5-2 (a
    problem --accept writes anyway)."""
    from phantom_pin import Phantom
    from phantom_pin.identification.data import io

    phantom = Phantom()
    theta, dtheta, ddtheta = sines(T10)
    io.write_log(tmp_path / "log.csv", T10, theta, model_torques(phantom, theta, dtheta, ddtheta) / [1, 1, 2.5])
    code, out, err = cli("identify", str(tmp_path / "log.csv"), "-o", str(tmp_path / "id.yaml"), "--accept",
                         "--torque-timing", "sampled")
    assert code == 0 and out.startswith("10001 samples") and "warning" not in out
    assert "phantom-pin: warning: (written with --accept) tau3 is 0.4 times joint 1's torque scale (gain 2.5" in err


def test_a_log_for_another_model_is_refused_by_identify_before_any_fit(tmp_path, cli):
    """identify refuses a log recorded for another model than the one given, before any fit, in
    one line naming both, nothing written."""
    path = recorded_trajectory(tmp_path / "log.csv", "# phantom-pin: model touch, convention report")
    code, out, err = cli("identify", path, "-o", tmp_path / "id.yaml")
    assert (code, out) == (2, "") and err.startswith(
        f"phantom-pin: error: LOG: {path} was written for the model touch in the report convention, read here for "
        "the model premium_1_5 in the report convention")
    assert not (tmp_path / "id.yaml").exists()
