"""estimate() on logs made here from the closed form: a three-frequency trajectory (exact
rates and accelerations), torques from the report's inverse dynamics plus the friction law,
so that the true beta is known (constants.nominal); and each of the fit's thresholds (the
torque guard, too little motion, the gains, negative friction) on logs of the model's own
torques (helpers.sines, helpers.model_torques)."""

import re

import numpy as np
import pytest

from helpers import CONFIG, REPORT, T10, model_torques, sines
from helpers import TRAJECTORY_AMPLITUDE as AMPLITUDE
from helpers import TRAJECTORY_PHASE as PHASE
from helpers import TRAJECTORY_RATE as RATE
from helpers import TRAJECTORY_W as W
from helpers import three_frequency_log as log
from phantom_pin import Device, Phantom, closed_form
from phantom_pin.cli import main
from phantom_pin.identification.data import io
from phantom_pin.identification.fitting import estimation
from phantom_pin.identification.structure import constants

PHANTOM = Phantom()
TRUTH = constants.nominal(PHANTOM.description)


def report(data, **kwargs):
    """The report structure's fit of a log whose torques are sampled (this module's)."""
    return estimation.estimate(data, PHANTOM, structure="report", timing="sampled", **kwargs)


def test_the_exact_log_gives_the_true_constants():
    fit = report(log())
    np.testing.assert_allclose(fit.beta, TRUTH, rtol=0, atol=2e-4 * np.abs(TRUTH).max())


def test_the_exact_log_gives_the_true_general_base_parameters():
    """The general structure's 24 base parameters of an exact log along an optimised excitation
    (15 iterations; the three-frequency trajectory above leaves the general base regressor's
    condition number above 1e3) against those of the report's numbers (structures.General.matrix
    at the shipped model's bodies), each within 2e-4 of its typical size (the base parameters mix
    kg, kg m and kg m^2)."""
    from phantom_pin.identification.fitting import excitation
    from phantom_pin.identification.structure.structures import General

    model = General(PHANTOM)
    t = np.arange(10001) / RATE
    theta, dtheta, ddtheta = excitation.optimise(PHANTOM, iterations=15, restarts=1).trajectory(t)
    tau = closed_form.inverse_dynamics(theta, dtheta, ddtheta, REPORT) + CONFIG.actuation.friction.torque(dtheta)
    fit = estimation.estimate(io.Log(t, theta, tau), PHANTOM, timing="sampled")
    truth = model.matrix @ model.prior
    assert fit.structure == "general" and len(fit.beta) == 24
    np.testing.assert_array_less(np.abs(fit.beta - truth), 2e-4 * (np.abs(model.matrix) @ model.scale))
    assert fit.problems == ()


def test_a_log_cut_in_mid_motion_is_identified_without_the_filters_edge_transients():
    """From 1.3 s to 9.1 s: the log starts and ends moving, where the zero-phase filter rings;
    the cut edges keep every constant within 3e-4 of the largest (without the cut: 0.26)."""
    fit = report(log(start=1.3, end=9.1))
    assert np.abs(fit.beta - TRUTH).max() < 3e-4 * np.abs(TRUTH).max()


def test_a_log_the_condition_gate_refused_is_identified(tmp_path, capsys):
    """The three-frequency log excites the report's 14 base parameters (condition number 10)
    but not the general structure's 24 well: its condition number lies between 2e3 and 1e5,
    which the gate (1e3, removed) refused. Its exact torques give the general base parameters
    within 2e-4 of their typical size (as excite's exact log, above), no problem, and identify
    prints the condition number as a diagnostic beside the predicted torque uncertainty, and
    writes the overlay."""
    from phantom_pin.identification.structure.structures import General

    assert report(log()).condition < 20
    fit = estimation.estimate(log(), PHANTOM, timing="sampled")
    assert 2e3 < fit.condition < 1e5, fit.condition
    model = General(PHANTOM)
    np.testing.assert_array_less(np.abs(fit.beta - model.matrix @ model.prior),
                                 2e-4 * (np.abs(model.matrix) @ model.scale))
    assert fit.problems == ()
    path = tmp_path / "log.csv"
    data = log()
    io.write_log(path, data.t, data.theta, data.tau)
    assert main(["identify", str(path), "-o", str(tmp_path / "id.yaml"), "--torque-timing", "sampled"]) == 0
    out = capsys.readouterr().out
    assert re.search(r"condition number [0-9.e+]+ \(a diagnostic: the fit is judged by its predicted torques\)", out)
    assert "predicted torque uncertainty (1 sigma, share of the torque RMS per joint): " in out
    header = (tmp_path / "id.yaml").read_text()
    assert "# predicted torque uncertainty (1 sigma, share of the torque RMS per joint): " in header


def test_a_joint_that_barely_moves_is_refused():
    """Joint 1 at 1 % of its amplitude (below MIN_SPEED = 0.01 rad/s nearly throughout): its
    equations are not fitted (a joint near rest may stick) and too few remain; at 10 % it is
    accepted."""
    with pytest.raises(io.LogError, match=r"too little motion: joint\(s\) 1 move faster than 0.01 rad/s"):
        report(log(joint1_scale=0.01))
    assert report(log(joint1_scale=0.1)).condition < 1e3


def test_each_joint_is_weighted_by_its_own_noise():
    """Noise of 3 mN m on joint 1 and 0.01 mN m on joints 2 and 3: weighted by each joint's
    own residual, the constants that joints 2 and 3 see (L, M22, M33, N2, N3 and their
    friction) keep small standard deviations, and every estimate lies within 6 of its
    standard deviations of the truth (the covariance is honest)."""
    fit = report(log(noise=(3e-3, 1e-5, 1e-5)))
    relative = dict(zip(constants.NAMES + constants.FRICTION_NAMES, fit.sigma / np.abs(TRUTH)))
    assert relative["L"] < 1e-3 and relative["M22"] < 3e-4 and relative["M33"] < 2e-3, relative
    assert relative["N2"] < 1e-4 and relative["N3"] < 3e-4, relative
    assert relative["viscous2"] < 5e-3 and relative["viscous3"] < 3e-2 and relative["coulomb3"] < 2e-3, relative
    assert relative["viscous1"] > 30 * relative["viscous2"]
    assert (np.abs(fit.beta - TRUTH) < 6 * fit.sigma).all(), (fit.beta - TRUTH) / fit.sigma


def test_identify_refuses_a_cutoff_the_rate_cannot_differentiate(tmp_path, capsys):
    """At 1 kHz the cutoff may reach 50 Hz (RATE_PER_CUTOFF): 60 Hz is refused, naming the rate
    it would need."""
    path = tmp_path / "log.csv"
    data = log()
    io.write_log(path, data.t, data.theta, data.tau)
    assert main(["identify", str(path), "-o", str(tmp_path / "id.yaml"), "--cutoff", "60"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "cutoff: 60 Hz needs a log at 1200 Hz or faster (this one: 1000 Hz" in err
    assert not (tmp_path / "id.yaml").exists()
    assert main(["identify", str(path), "-o", str(tmp_path / "id.yaml"), "--cutoff", "50", "--torque-timing", "sampled",
                 "--structure", "report"]) == 0


def test_a_log_of_phantom_pins_own_simulator_gives_the_true_constants():
    """The device simulator (phantom_pin.simulate: Pinocchio's dynamics with the rotors, the
    friction law, stops and saturation, RK4 with a zero-order hold at 1 kHz) tracks this
    module's trajectory with its inverse dynamics as feed-forward plus PD (5 N m/rad, 0.05 N m
    s/rad); the log of its true angles and applied torques gives every constant within 0.5 %
    of the largest."""
    from phantom_pin import Device, simulate

    reference = log()
    assert Device().within_limits(reference.theta).all()                    # no stop is met
    index = {round(t * RATE): k for k, t in enumerate(reference.t)}
    rates = np.gradient(reference.theta, reference.t, axis=0)

    def controller(t, theta, dtheta):
        k = index[round(t * RATE)]
        return reference.tau[k] + 5.0 * (reference.theta[k] - theta) + 0.05 * (rates[k] - dtheta)

    dtheta0 = (np.cos(PHASE) * np.arange(1, 4) * W) @ AMPLITUDE.T          # the trajectory's rate at t = 0
    result = simulate(reference.theta[0], 10.0, controller, dtheta0=dtheta0)
    assert np.abs(result.theta - reference.theta).max() < 0.01             # it tracked
    fit = estimation.estimate(io.Log(result.t, result.theta, result.tau), PHANTOM, structure="report")  # held
    assert np.abs(fit.beta - TRUTH).max() < 5e-3 * np.abs(TRUTH).max(), (fit.beta - TRUTH) / np.abs(TRUTH).max()


def test_identify_writes_nothing_when_the_overlay_is_not_physical(tmp_path, capsys, monkeypatch):
    """The overlay is checked (describe() and its physical check of every link) before it is
    written: here that check refuses it, and no file appears."""
    from phantom_pin.exceptions import ParameterFileError
    from phantom_pin.identification.verdict import overlays

    def refuse(*args, **kwargs):
        raise ParameterFileError("link forearm_link: mass must be positive (kg), got -1.0")

    path = tmp_path / "log.csv"
    data = log()
    io.write_log(path, data.t, data.theta, data.tau)
    monkeypatch.setattr(overlays, "describe", refuse)
    assert main(["identify", str(path), "-o", str(tmp_path / "id.yaml"), "--torque-timing", "sampled",
                 "--structure", "report"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "identified parameters not physically valid" in err
    assert not (tmp_path / "id.yaml").exists()


def test_the_log_reader_takes_the_dialects_users_write(tmp_path):
    """The same log as comma-separated plain CSV, and with a UTF-8 byte order mark, semicolons,
    quoted upper-case headers and comment lines, and with tabs and units in the header: the
    same numbers. A bad row is named by its line."""
    data = log(end=3.0)
    plain = tmp_path / "plain.csv"
    io.write_log(plain, data.t, data.theta, data.tau)
    table = np.loadtxt(plain, delimiter=",", skiprows=1)
    rows = [";".join(repr(float(v)) for v in row) for row in table]
    spreadsheet = tmp_path / "spreadsheet.csv"
    spreadsheet.write_text("\ufeff# exported by a spreadsheet\n" + ";".join(f'"{c.upper()}"' for c in io.LOG_COLUMNS)
                           + "\n" + "\n# a pause\n".join(rows[:5]) + "\n" + "\n".join(rows[5:]) + "\n",
                           encoding="utf-8")
    tabs = tmp_path / "tabs.tsv"
    units = ("s",) + ("rad",) * 3 + ("N m",) * 3
    tabs.write_text("\t".join(f"{c} [{u}]" for c, u in zip(io.LOG_COLUMNS, units)) + "\n"
                    + "\n".join("\t".join(repr(float(v)) for v in row) for row in table) + "\n")
    reference = io.read_log(plain)
    for path in (spreadsheet, tabs):
        other = io.read_log(path)
        for name in ("t", "theta", "tau"):
            np.testing.assert_array_equal(getattr(other, name), getattr(reference, name))
    broken = tmp_path / "broken.csv"
    lines = plain.read_text().splitlines()
    lines[7] = lines[7].replace(",", ",x", 1)
    broken.write_text("\n".join(lines) + "\n")
    with pytest.raises(io.LogError, match="line 8 holds a value that is not a number"):
        io.read_log(broken)


def test_the_log_reader_reads_simulates_own_csv(tmp_path, capsys):
    """phantom-pin simulate --format csv writes t, theta and the applied tau with units in its
    header, among other columns: the log reader takes it as it is."""
    assert main(["simulate", "--theta0", "0.2", "0.5", "0.8", "--duration", "3", "--format", "csv",
                 "-o", str(tmp_path / "run.csv")]) == 0
    log_ = io.read_log(tmp_path / "run.csv")
    assert log_.t.shape == (3001,) and log_.theta.shape == (3001, 3)


def test_the_identification_api_checks_its_input(tmp_path):
    """One InvalidInputError or LogError naming the argument (before: LinAlgError, TypeError,
    silent NaN, or write_log overwriting a file); the public names live in the package."""
    import phantom_pin.identification as identification
    from phantom_pin import InvalidInputError

    assert identification.estimate is estimation.estimate and identification.write_log is io.write_log
    data = log(end=3.0)
    path = tmp_path / "log.csv"
    identification.write_log(path, data.t, data.theta, data.tau)
    with pytest.raises(io.LogError, match="^path: .* exists; use force=True"):
        identification.write_log(path, data.t, data.theta, data.tau)
    identification.write_log(path, data.t, data.theta, data.tau, force=True)
    with pytest.raises(InvalidInputError, match="^theta: "):
        identification.write_log(tmp_path / "b.csv", data.t, data.theta[:, :2], data.tau)
    with pytest.raises(io.LogError, match=r"^log: expected t \(N,\), theta \(N, 3\), tau \(N, 3\)"):
        identification.write_log(tmp_path / "c.csv", data.t[:-1], data.theta, data.tau)
    assert not (tmp_path / "b.csv").exists() and not (tmp_path / "c.csv").exists()
    for kwargs, argument in (({"log": "log.csv"}, "log"), ({"phantom": "premium_1_5"}, "phantom"),
                             ({"cutoff": float("nan")}, "cutoff"), ({"prior_weight": -1.0}, "prior_weight"),
                             ({"structure": "full"}, "structure"), ({"timing": "late"}, "timing"),
                             ({"prior_spread": 0.0}, "prior_spread"), ({"prior_spread": float("nan")}, "prior_spread"),
                             ({"prior_spread": "30 %"}, "prior_spread")):
        arguments = {"log": data, "phantom": PHANTOM, **kwargs}
        with pytest.raises(InvalidInputError, match=f"^{argument}: "):
            identification.estimate(**arguments)
    with pytest.raises(InvalidInputError, match="^fit: "):
        identification.overlay("fit.yaml")
    with pytest.raises(InvalidInputError, match="^device: "):
        identification.track("premium_1_5", data.t, data.theta, data.theta, data.tau)
    with pytest.raises(InvalidInputError, match="^torque_noise: "):
        identification.track(Device(), data.t, data.theta, data.theta, data.tau, torque_noise=-1.0)


@pytest.mark.parametrize("call, argument", [
    (lambda: io.read_log(None), "path"), (lambda: io.Log(np.arange(10.0), np.zeros((9, 3)), np.zeros((10, 3))), "log"),
    (lambda: io.Log(np.arange(10.0)[::-1], np.zeros((10, 3)), np.zeros((10, 3))), "log"),
    (lambda: estimation.estimate(log(end=3.0), PHANTOM, cutoff=1e-9), "cutoff"),
    (lambda: estimation.estimate(log(end=3.0), PHANTOM, progress=5), "progress"),
])
def test_the_log_checks_its_arguments(call, argument):
    """Each bad argument a new user tried (a review): one PhantomPinError and ValueError naming
    it, before any work (before: LinAlgError, TypeError, RuntimeError, a silent result)."""
    from phantom_pin import PhantomPinError

    with pytest.raises(PhantomPinError, match=f"^{argument}: ") as error:
        call()
    assert isinstance(error.value, ValueError)


# -- each threshold against a log built here with a known truth (helpers.sines) ----------------


def test_a_log_with_torques_beyond_1000_n_m_is_refused_at_once(monkeypatch):
    """A log whose torques reach beyond 1000 N m is refused at once, as its message says: the
    model's torques with 2000 N m on joint 2's, refused before any fit (the filter, the first
    costly stage, is never reached)."""
    from phantom_pin import Phantom
    from phantom_pin.identification.data import io
    from phantom_pin.identification.fitting import estimation

    def unreachable(*args, **kwargs):
        raise AssertionError("filtered before the refusal")

    monkeypatch.setattr(estimation, "filtered", unreachable)
    phantom = Phantom()
    theta, dtheta, ddtheta = sines(T10)
    tau = model_torques(phantom, theta, dtheta, ddtheta)
    tau[100, 1] = 2000.0
    with pytest.raises(io.LogError, match=r"tau2: the log's torques reach 2e\+03 N m, more than 1000 N m"):
        estimation.estimate(io.Log(T10, theta, tau), phantom)


def test_a_joint_moving_in_fewer_than_50_samples_is_too_little_motion():
    """A joint moving in fewer than 50 samples is too little motion. Joint 3 swings 3.4 mrad at
    0.5 Hz (peak 10.7 mrad/s): at --min-speed 10.5 mrad/s the filtered log has between 5 and 50
    of its samples moving (counted by filtering.filtered), which is too little motion."""
    from phantom_pin import Phantom
    from phantom_pin.identification.data import io
    from phantom_pin.identification.fitting import estimation, filtering

    phantom = Phantom()
    theta, dtheta, ddtheta = sines(T10)
    w, amplitude = np.pi, 0.0034
    theta[:, 2], dtheta[:, 2], ddtheta[:, 2] = (0.45 + amplitude * np.sin(w * T10), amplitude * w * np.cos(w * T10),
                                                -amplitude * w * w * np.sin(w * T10))
    log = io.Log(T10, theta, model_torques(phantom, theta, dtheta, ddtheta))
    moving = filtering.filtered(log, 20.0, phantom.config.actuation.friction, min_speed=0.0105).moving.sum(axis=0)
    assert 5 < moving[2] < 50 and (moving[:2] >= 50).all(), moving
    with pytest.raises(io.LogError, match="too little motion: joint.s. 3 move faster than 0.0105 rad/s in fewer "
                                          "than 50 samples"):
        estimation.estimate(log, phantom, min_speed=0.0105)


@pytest.mark.parametrize("gain, corrected", [(1.005, False), (2.5, None)])
def test_a_gain_is_corrected_only_beyond_1_percent_and_refused_beyond_2(gain, corrected):
    """A torque gain is corrected only beyond 1 % AND 4 sigma from 1, and refused outside 0.5-2
    as no drive's tolerance. The model's own torques with joint 2's (or 3's) logged 1 / gain
    times too small: 0.5 % off (thousands of sigma on a noiseless log, but within 1 %) is
    estimated and kept at 1; 2.5 is refused."""
    from phantom_pin import Phantom
    from phantom_pin.identification.data import io
    from phantom_pin.identification.fitting import estimation

    phantom = Phantom()
    theta, dtheta, ddtheta = sines(T10)
    joint = 1 if corrected is not None else 2
    tau = model_torques(phantom, theta, dtheta, ddtheta)
    tau[:, joint] /= gain
    fit = estimation.estimate(io.Log(T10, theta, tau), phantom, timing="sampled")
    values, sigma = fit.gains_estimated
    assert values[joint] == pytest.approx(gain, rel=1e-4) and abs(values[joint] - gain) < 10 * sigma[joint] + 1e-4
    if corrected is False:
        assert abs(values[joint] - 1) > 4 * sigma[joint] and fit.gains[joint] == 1.0
    else:
        assert any(f"tau3 is {1 / gain:.3g} times joint 1's torque scale (gain {gain:.3g}, outside 0.5-2" in p
                   for p in fit.problems), fit.problems


def test_friction_estimated_3_to_30_sigma_below_zero_is_refused():
    """Friction estimated well below zero (here 10 sigma, between 3 and 30) is refused as
    negative. Two logs with the same seeded torque noise (2 mN m): joint 1's Coulomb torque 0
    gives its standard deviation s; -10 s as the truth is estimated about 10 s below zero and
    refused as negative."""
    from phantom_pin import Phantom
    from phantom_pin.identification.data import io
    from phantom_pin.identification.fitting import estimation

    phantom = Phantom()
    theta, dtheta, ddtheta = sines(T10)
    noise = np.random.default_rng(7).normal(0, 2e-3, (len(T10), 3))
    law = phantom.config.actuation.friction

    def fit(coulomb1):
        tau = model_torques(phantom, theta, dtheta, ddtheta, (coulomb1, *law.coulomb[1:])) + noise
        return estimation.estimate(io.Log(T10, theta, tau), phantom, timing="sampled")

    s = fit(0.0).friction[1][3]
    refused = fit(-10 * s)
    value, sigma = refused.friction[0][3], refused.friction[1][3]
    assert -15 < value / sigma < -5, value / sigma
    assert any(p.startswith("negative friction (") for p in refused.problems), refused.problems
