"""Identification of a device that is NOT of the report's structure: the report's Premium 1.5 with
every body changed (masses 10-20 %, centres of mass 1-6 mm off the segments' axes, products of
inertia; our own numbers, every link physical), friction, 2 mN m of torque noise and its encoders,
simulated by the device's own plant tracking `phantom-pin excite`'s trajectory. Judged against the
device itself on a held-out trajectory and on random states; then the logs a new user gets wrong
(signs, units, ratios, degrees, unrelated torques, a slow log) must be refused."""

import re
from types import SimpleNamespace

import numpy as np
import pytest

from helpers import CONFIG, excitation_file, run_cli
from phantom_pin import Device, Phantom, describe
from phantom_pin.config import read_overrides
from phantom_pin.config.sampling import sample_postures
from phantom_pin.description.inertial import INERTIA_KEYS, Inertial, problem, uncarve
from phantom_pin.identification.data import io, simulation
from phantom_pin.identification.fitting import estimation

#: Per body: factor on mass and inertia, centre of mass offset (m), products xy, xz, yz (kg m^2).
CHANGES = {
    "turret_link": (1.1, (0.004, -0.006, 0.003), (2e-5, -3e-5, 1.5e-5)),
    "upper_arm_link": (1.15, (0.0, 0.003, 0.002), (1.2e-5, -8e-6, 5e-6)),
    "crank_link": (0.9, (0.002, 0.0, 0.001), (-6e-6, 4e-6, 9e-6)),
    "lower_bar_link": (1.2, (0.0, 0.0015, -0.001), (0.0, 0.0, 0.0)),    # a thin bar: products break it
    "forearm_link": (0.85, (0.0015, -0.001, 0.0), (0.0, 2e-7, -1e-7)),
}
VISCOUS, COULOMB, NOISE = 6e-4, 0.012, 0.002      # N m s/rad, N m, N m (1 sigma)
#: identify's choices a test is not about, given (each chosen on held-out quarters of the log otherwise:
#: the fixture's identify runs the defaults): the friction threshold and the torque timing.
GIVEN = ("--min-speed", "0.01", "--torque-timing", "held")


def device_overrides() -> dict:
    """The device as --params keys: the report's five bodies in full (uncarve), changed."""
    keys = {"actuation.friction.viscous": VISCOUS, "actuation.friction.coulomb": COULOMB}
    for name, body in uncarve(CONFIG.links, CONFIG.kinematics).items():
        factor, offset, (xy, xz, yz) = CHANGES[name]
        xx, _, _, yy, _, zz = (factor * v for v in body.inertia)
        changed = Inertial(factor * body.mass, tuple(np.add(body.com, offset)), (xx, xy, xz, yy, yz, zz))
        assert problem(changed) is None, (name, problem(changed))
        keys[f"links.{name}.mass"] = changed.mass
        keys.update({f"links.{name}.com.{i}": float(c) for i, c in enumerate(changed.com)})
        keys.update({f"links.{name}.inertia.{k}": float(v) for k, v in zip(INERTIA_KEYS, changed.inertia)})
    return keys


DEVICE = Device(Phantom(describe(overrides=device_overrides())))


def cli(*arguments) -> tuple[int, str, str]:
    return run_cli("--quiet", *arguments)


def torques(device: Device, theta, dtheta, ddtheta) -> np.ndarray:
    """A device's joint torques (N m): its rigid body with rotors, and its friction."""
    return device.phantom.inverse_dynamics(theta, dtheta, ddtheta) + device.friction(dtheta)


def rms(error, reference) -> float:
    return float(np.sqrt((error**2).mean() / (reference**2).mean()))


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    folder = tmp_path_factory.mktemp("general")
    # `phantom-pin excite -o traj.csv --restarts 1`'s file (the defaults' too: of their two starts
    # the first is the better one here), from its recorded series (helpers.EXCITATIONS)
    excitation_file(folder / "traj.csv", "premium_1_5")
    assert cli("excite", "-o", folder / "held_out.csv", "--seed", "5", "--iterations", "5")[0] == 0
    t, theta, dtheta, _, tau = io.read_trajectory(folder / "traj.csv")
    log = simulation.track(DEVICE, t, theta, dtheta, tau, torque_noise=NOISE, seed=1)
    io.write_log(folder / "log.csv", log.t, log.theta, log.tau)
    code, general, err = cli("identify", folder / "log.csv", "-o", folder / "general.yaml")
    assert code == 0, err
    code, report, err = cli("identify", folder / "log.csv", "-o", folder / "report.yaml", "--structure", "report")
    assert code == 0, err
    return SimpleNamespace(folder=folder, log=log, general=general, report=report,
                           identified=Device(Phantom(describe(overrides=read_overrides(folder / "general.yaml")))),
                           structured=Device(Phantom(describe(overrides=read_overrides(folder / "report.yaml")))))


def test_the_general_model_predicts_a_held_out_trajectory_within_half_a_percent(run):
    t, theta, dtheta, ddtheta, _ = io.read_trajectory(run.folder / "held_out.csv")
    truth = torques(DEVICE, theta, dtheta, ddtheta)
    general = rms(torques(run.identified, theta, dtheta, ddtheta) - truth, truth)
    report = rms(torques(run.structured, theta, dtheta, ddtheta) - truth, truth)
    shipped = rms(torques(Device(), theta, dtheta, ddtheta) - truth, truth)
    print(f"held-out trajectory: general {general:.4%}, report structure {report:.4%}, shipped {shipped:.4%}")
    assert general < 0.005 and report > 3 * general and shipped > 0.05


def test_the_general_model_predicts_random_states_within_half_a_percent(run):
    rng = np.random.default_rng(17)
    theta = sample_postures(CONFIG.limits, 500, rng, draws=2000)
    dtheta, ddtheta = rng.normal(0, 2, (500, 3)), rng.normal(0, 20, (500, 3))
    truth = DEVICE.phantom.inverse_dynamics(theta, dtheta, ddtheta)        # the rigid body alone
    general = rms(run.identified.phantom.inverse_dynamics(theta, dtheta, ddtheta) - truth, truth)
    report = rms(run.structured.phantom.inverse_dynamics(theta, dtheta, ddtheta) - truth, truth)
    print(f"random states: general {general:.4%}, report structure {report:.4%}")
    assert general < 0.005 and report > 3 * general


def test_friction_comes_back_within_five_percent(run):
    keys = read_overrides(run.folder / "general.yaml")
    for j in (1, 2, 3):     # each joint's own, written per joint
        assert keys[f"actuation.friction.viscous.joint{j}"] == pytest.approx(VISCOUS, rel=0.05)
        assert keys[f"actuation.friction.coulomb.joint{j}"] == pytest.approx(COULOMB, rel=0.05)


def test_identify_says_the_general_model_is_needed_and_prints_the_report_fit_beside(run):
    general = [float(v) for v in re.search(r"residual RMS per joint \[N m\]: (\S+) \(.*?, (\S+) \(.*?, (\S+) \(",
                                           run.general).groups()]
    report = [float(v) for v in re.search(r"the report structure leaves (\S+), (\S+), (\S+) N m", run.general).groups()]
    assert all(r > 1.2 * g for g, r in zip(general, report)), (general, report)
    assert "recommendation: the report's structure leaves up to" in run.general
    assert "recommendation:" in run.report and "identify with --structure general" in run.report
    assert "general structure, 24 base parameters" in run.general


def test_the_overlay_is_a_model_in_full_that_mujoco_agrees_with(run, tmp_path):
    """The general overlay turns the report's model into one in full (links.*): its URDF and MJCF
    are written, and MuJoCo's mass matrix and gravity (through the mimic coupling) equal
    Pinocchio's on the identified model to 1e-9 of their largest entries."""
    import mujoco

    from helpers import MujocoArm
    from phantom_pin.dynamics.coupling import Coupling

    overlay = run.folder / "general.yaml"
    assert run.identified.config.report is None
    for kind in ("urdf", "mjcf"):
        assert cli(kind, "--params", overlay, "-o", tmp_path / f"id.{kind}")[0] == 0
    arm = MujocoArm(mujoco.MjModel.from_xml_path(str(tmp_path / "id.mjcf")),
                    Coupling((tmp_path / "id.urdf").read_text()))
    phantom = run.identified.phantom
    for q in sample_postures(CONFIG.limits, 20, np.random.default_rng(3), draws=80):
        mass, gravity = arm.reduced_mass_and_gravity(q)
        np.testing.assert_allclose(mass, phantom.mass_matrix(q), rtol=0, atol=1e-9 * np.abs(mass).max())
        np.testing.assert_allclose(gravity, phantom.gravity(q), rtol=0, atol=1e-9 * np.abs(gravity).max())


def _bad(run, tau=None, theta=None, step=1):
    log = run.log
    return io.Log(log.t[::step], (log.theta if theta is None else theta)[::step],
                  (log.tau if tau is None else tau)[::step])


BAD_LOGS = {
    "signs flipped": (lambda r: _bad(r, tau=-r.log.tau), "are their signs flipped"),
    "one amplifier flipped": (lambda r: _bad(r, tau=r.log.tau * [1, -1, 1]), "tau2's sign is flipped"),
    "all-zero torques": (lambda r: _bad(r, tau=0 * r.log.tau), "constant torques over the whole log"),
    "unrelated torques": (lambda r: _bad(r, tau=np.random.default_rng(0).permutation(r.log.tau)),
                          "the torques do not follow the motion"),
    "degrees": (lambda r: _bad(r, theta=np.degrees(r.log.theta)), "are they in degrees"),
    "mN m": (lambda r: _bad(r, tau=1000 * r.log.tau), "times the model's prediction along the motion: in mN m?"),
    # before: NumPy's overflow warnings and "SVD did not converge", naming nothing
    "angles scaled by 1e300": (lambda r: _bad(r, theta=1e300 * r.log.theta), "rad beyond the stops, more than a turn"),
    "torques scaled by 1e300": (lambda r: _bad(r, tau=1e300 * r.log.tau), "N m, more than 1000 N m: not joint torques"),
    "a 10 Hz log": (lambda r: _bad(r, step=100), "cutoff: 20 Hz needs a log at 400 Hz or faster (this one: 10 Hz"),
    "tau2 in another unit": (lambda r: _bad(r, tau=r.log.tau * [1, 10, 1]), "tau2: the logged torques are 9."),
    "tau3 2.5 times the others": (lambda r: _bad(r, tau=r.log.tau * [1, 1, 2.5]),
                                  "tau3 is 2.5 times joint 1's torque scale (gain 0.4"),
}


@pytest.mark.parametrize("case", BAD_LOGS)
def test_a_bad_log_is_refused_in_one_line_and_nothing_is_written(run, case, tmp_path):
    make, message = BAD_LOGS[case]
    log = make(run)
    io.write_log(tmp_path / "log.csv", log.t, log.theta, log.tau)
    code, out, err = cli("identify", tmp_path / "log.csv", "-o", tmp_path / "id.yaml", *GIVEN)
    assert code == 2 and err.count("\n") == 1 and message in err, err
    assert not (tmp_path / "id.yaml").exists()


#: The bad logs whose torques' size or sign shows against the prior's prediction without any fit.
BEFORE_ANY_FIT = ("signs flipped", "one amplifier flipped", "mN m", "tau2 in another unit")


@pytest.mark.parametrize("case", BEFORE_ANY_FIT)
def test_a_wrong_unit_or_sign_is_refused_before_any_fit(run, case, monkeypatch):
    """Fail fast (issue 39, 5): a log in mN m, with flipped signs or one joint in another unit is
    refused by identify() with the same first line as the full pipeline's verdict, before the
    timing, gains and fit stages run (they are replaced by a failure here); with accept=True the
    pipeline runs and lists the same problem (the physical reason, independent of the stage)."""
    from phantom_pin.identification import RefusedError, identify

    make, message = BAD_LOGS[case]
    log = make(run)

    def unreachable(*args, **kwargs):
        raise AssertionError("a costly stage ran before the refusal")

    with monkeypatch.context() as patched:
        patched.setattr(estimation, "solve_gains", unreachable)
        patched.setattr(estimation, "estimate_delay", unreachable)
        with pytest.raises(RefusedError) as refused:
            identify(log, Phantom(), delay=None)        # identify's prior: the default model's
    assert message in refused.value.problems[0], refused.value.problems
    accepted = estimation.estimate(log, Phantom())
    assert any(message in problem for problem in accepted.problems), accepted.problems


def gains(output: str) -> np.ndarray:
    """The estimated gains of joints 2 and 3 and their standard deviations that identify printed."""
    found = re.findall(r"joint([23]) (\S+) \+- (\S+) \(", output.split("torque gains relative to joint 1")[1])
    assert [j for j, _, _ in found] == ["2", "3"], output
    return np.array([[float(g), float(s)] for _, g, s in found])


#: Logs whose torques are not the device's joint torques on joints 2 and 3: the factor of the
#: logged torques against the device's (the gain identify must find is its inverse).
GAIN_LOGS = {
    "joint 2's torque constant 2 % above its driver's": [1, 1 / 1.02, 1],
    "converted with ratio 11.2 instead of 11.6": [1, 11.2 / 11.6, 11.2 / 11.6],
}


@pytest.mark.parametrize("case", GAIN_LOGS)
def test_a_joints_torque_gain_is_found_corrected_and_reported(run, case, tmp_path):
    """The device's log with joint 2's (and 3's) torques scaled: identify estimates each joint's
    gain relative to joint 1, and the scaled log's estimate over the true log's is the inverse
    of the scale within 2e-4 (the fit is equivariant to a joint's torque scale: whatever bias the
    log's noise leaves cancels); within 4 standard deviations of it on its own; it corrects the
    written model, whose rigid body predicts 500 random states within 0.5 % of the device's and
    friction within 5 %, where the same log with --fixed-gains is off by more than 1.5 %; and
    it tells what to write into the driver (and, for the ratios, that 11.2 was used)."""
    factor = np.array(GAIN_LOGS[case])
    io.write_log(tmp_path / "log.csv", run.log.t, run.log.theta, run.log.tau * factor)
    code, out, err = cli("identify", tmp_path / "log.csv", "-o", tmp_path / "id.yaml", *GIVEN)
    assert code == 0, err
    found = gains(out)                 # as applied (corrected) or estimated (kept at 1)
    scaled_fit, clean_fit = (estimation.estimate(io.Log(run.log.t, run.log.theta, run.log.tau * f), Phantom(),
                                                 delay=None) for f in (factor, np.ones(3)))
    ratio = scaled_fit.gains_estimated[0] / clean_fit.gains_estimated[0]
    print(case, "gains:", found.tolist(), "estimated over the true log's:", ratio)
    np.testing.assert_allclose(ratio[1:], 1 / factor[1:], rtol=2e-4)
    assert (np.abs(found[:, 0] - 1 / factor[1:]) < 4 * found[:, 1]).all() and (found[:, 1] < 5e-3).all()
    scaled = [j for j in (1, 2) if factor[j] != 1]
    for j in scaled:    # the log's scale against joint 1's (1 / the gain), to the 4 digits printed
        shown = float(re.search(rf"tau{j + 1} is (\S+) times", err).group(1))     # the gain warning: stderr
        assert abs(shown - factor[j]) < 4 * found[j - 1, 1] + 1e-4, (shown, factor[j])
    assert "torque constant in your driver by" in err
    assert "corrected better on 4 of 4 quarters): corrected" in out, out     # validated on held-out quarters
    if len(scaled) == 2:
        ratios = [float(v) for v in re.findall(r"(\S+) instead of the model's 11.6", err)]
        assert len(ratios) == 2 and all(abs(r - 11.2) < 0.1 for r in ratios), ratios
    rng = np.random.default_rng(17)
    theta = sample_postures(CONFIG.limits, 500, rng, draws=2000)
    dtheta, ddtheta = rng.normal(0, 2, (500, 3)), rng.normal(0, 20, (500, 3))
    truth = DEVICE.phantom.inverse_dynamics(theta, dtheta, ddtheta)
    errors = {}
    for flag in ((), ("--fixed-gains",)):
        code, _, err = cli("identify", tmp_path / "log.csv", "-o", tmp_path / "id.yaml", "--force", *GIVEN, *flag)
        identified = Device(Phantom(describe(overrides=read_overrides(tmp_path / "id.yaml"))))
        errors[flag] = rms(identified.phantom.inverse_dynamics(theta, dtheta, ddtheta) - truth, truth)
        if not flag:
            friction = identified.friction(dtheta) - DEVICE.friction(dtheta)
            assert np.abs(friction).max() < 0.05 * np.abs(DEVICE.friction(dtheta)).max()
    print(case, "random states:", errors)
    assert errors[()] < 0.005 and errors[("--fixed-gains",)] > 0.015


def test_forced_friction_is_never_negative(run, tmp_path):
    """--accept writes the sign-flipped log's result, with its problems as comments, and the
    friction it writes is not the negative estimate: 0 or more."""
    io.write_log(tmp_path / "log.csv", run.log.t, run.log.theta, -run.log.tau)
    code, out, err = cli("identify", tmp_path / "log.csv", "-o", tmp_path / "id.yaml", "--force")
    assert code == 2 and "--accept writes it anyway" in err and not (tmp_path / "id.yaml").exists()
    code, out, err = cli("identify", tmp_path / "log.csv", "-o", tmp_path / "id.yaml", "--accept")
    assert code == 0 and "phantom-pin: warning: (written with --accept) tau: the logged torques are -0.99" in err, err
    assert "negative friction (viscous1" in err and "warning" not in out
    text = (tmp_path / "id.yaml").read_text()
    assert "# problem, written with --accept:" in text
    code, out, err = cli("identify", tmp_path / "log.csv", "-o", tmp_path / "id.yaml", "--accept")
    assert code == 2 and "exists; use --force to overwrite it" in err   # --accept is no licence to overwrite
    keys = read_overrides(tmp_path / "id.yaml")
    written = [keys[f"actuation.friction.{kind}.joint{j}"] for kind in ("viscous", "coulomb") for j in (1, 2, 3)]
    assert min(written) >= 0        # all six written, each 0 or more


def test_a_gain_the_held_out_quarters_do_not_confirm_is_kept_at_1(run, tmp_path):
    """Joint 2's torques 6 % low in the log's second quarter only (a gain that is not one gain:
    a drive heating, a loose connector): over the whole log its gain passes the evidence rule
    (more than 1 % and 4 standard deviations from 1), but estimated on three quarters and
    judged on the fourth it does not predict better on every quarter (GAIN_EVIDENCE's
    candidates are validated, selection.validate_gains): identify keeps it at 1, prints both
    held-out residuals and warns that the log cannot tell. The uniform error of
    test_a_joints_torque_gain_is_found_corrected_and_reported is corrected, better on 4 of 4."""
    factor = np.ones_like(run.log.tau)
    n = len(run.log.t)
    factor[n // 4:n // 2, 1] = 1 / 1.06
    log = io.Log(run.log.t, run.log.theta, run.log.tau * factor)
    fit = estimation.estimate(log, Phantom(), delay=None)
    values, sigma = fit.gains_estimated
    print("gains estimated:", values, sigma, "held-out:", fit.gain_scores)
    assert abs(values[1] - 1) > max(estimation.GAIN_NOTED, estimation.GAIN_EVIDENCE * sigma[1])   # a candidate
    assert (fit.gains == 1).all() and fit.gain_scores["quarters better"] < 4
    io.write_log(tmp_path / "log.csv", log.t, log.theta, log.tau)
    code, out, err = cli("identify", tmp_path / "log.csv", "-o", tmp_path / "id.yaml")
    assert code == 0, err
    assert "(kept at 1: correcting it did not improve the held-out prediction)" in out
    assert re.search(r"torque gain correction checked on held-out quarters of the log \(weighted residual: kept at 1 "
                     r"\S+ %, corrected \S+ % of the torque RMS; corrected better on [0-3] of 4 quarters\): kept at 1",
                     out), out
    assert "joint 2's torque gain" in err and "kept at 1 (the prior's), the log cannot tell" in err, err
    assert "torque constant in your driver" not in err


def _printed_shares(output: str, start: str, part: int = 0) -> np.ndarray:
    """The ``part``-th three per-joint shares (%) of the printed line that starts with ``start``."""
    line = next(line for line in output.splitlines() if line.startswith(start))
    shares = [float(v) for v in re.findall(r"([0-9.e+-]+) %", line.split(": ", 1)[1])]
    return np.array(shares[3 * part:3 * part + 3]) / 100


def test_the_printed_expected_error_covers_the_held_out_trajectory(run):
    """Issue 39, 3: the expected error on unseen motion that identify prints (1 sigma per joint,
    prediction.CALIBRATION times the log's-noise sigma) covers at 2 sigma the written model's
    rigid-body error on the held-out trajectory on every joint, against the device's own inverse
    dynamics (rotors included, friction not: the figures table's measure)."""
    expected = _printed_shares(run.general, "expected error on unseen motion")
    noise = _printed_shares(run.general, "predicted torque uncertainty", part=1)    # over the states
    np.testing.assert_allclose(expected, 5.0 * noise, rtol=0.11)   # printed to 2 digits: up to 5.5 % off apiece
    _, theta, dtheta, ddtheta, _ = io.read_trajectory(run.folder / "held_out.csv")
    truth = DEVICE.phantom.inverse_dynamics(theta, dtheta, ddtheta)
    error = np.sqrt(((run.identified.phantom.inverse_dynamics(theta, dtheta, ddtheta) - truth) ** 2).mean(0)
                    / (truth**2).mean(0))
    print("held-out error per joint", error, "printed 2 sigma", 2 * expected, "the log's noise alone", 2 * noise)
    assert (error <= 2 * expected).all(), (error, expected)
