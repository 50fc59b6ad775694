"""Closed-loop noise (identification.instruments): a device that is NOT the prior (the CAD-built
Premium 1.5, identified on the shipped model with its lengths) tracks a lab's sum of sines in
its servo loop with 10 mA of current noise in the plant (not in the log), the loop feeding the
noise back into the motion. Least squares on that log is biased: the delay it estimates runs
to the bracket's -4 ms and viscous friction to +60 %. Given the reference the loop tracked,
the instrumental-variable estimate finds the simulation's own delay (none) and friction (the
device's configured law), and a written model within the log's predicted uncertainty.
Seeded; a 60 s simulation (about 2 s), 20 s without the noise, and three estimates."""

import dataclasses
import functools

import numpy as np
import pytest

from helpers import run_cli, sum_of_sines
from phantom_pin import Device, Phantom, describe
from phantom_pin.config import read_overrides
from phantom_pin.config.sampling import random_states
from phantom_pin.exceptions import InvalidInputError, LogError, PhantomPinError
from phantom_pin.identification import estimate, overlay
from phantom_pin.identification.data import simulation
from phantom_pin.identification.verdict import result
from phantom_pin.interfaces import conventions

TRUTH = describe("premium_1_5_cad")
#: The lab measured its lengths: the prior is the shipped model with the device's.
PRIOR = Phantom(describe("premium_1_5", overrides=dataclasses.asdict(TRUTH.config.kinematics)))
DURATION, AMPLITUDE, SEED = 60.0, 0.4, 1
#: s of the log the command-line test identifies (its first part; the log is at 1 kHz).
CLI_DURATION = 20.0


@functools.cache
def closed_loop(current: float = 0.010, duration: float = DURATION):
    """(the log, the reference (t, theta)): the device tracking the sum of sines with the prior's
    torques and friction as feed-forward, PD feedback, ``current`` A (1 sigma) of current noise
    in the plant (10 mA), for ``duration`` s."""
    device = Device(Phantom(TRUTH))
    t, theta, dtheta, ddtheta = sum_of_sines(duration, AMPLITUDE, SEED)
    tau = PRIOR.inverse_dynamics(theta, dtheta, ddtheta) + PRIOR.config.actuation.friction.torque(dtheta)
    noise = np.asarray(device.joint_torques(np.full(3, current)), float)       # N m per joint
    log = simulation.track(device, t, theta, dtheta, tau, torque_noise=noise, quantization=False, seed=SEED)
    return log, (t, theta)


def held_out_error(fit):
    """The written model's rigid-body torque error on 500 seeded states inside the stops, worst
    joint, as a share of its torque RMS, against the device's own inverse dynamics."""
    keys, _ = overlay(fit, None, PRIOR.config)
    model, truth = Phantom(describe(PRIOR.config.folder, overrides=keys)), Phantom(TRUTH)
    states = random_states(PRIOR.config.limits, 500, 7)
    true = truth.inverse_dynamics(*states)
    return float(np.sqrt(((model.inverse_dynamics(*states) - true) ** 2).mean(0) / (true**2).mean(0)).max())


def friction_error(fit):
    """The estimated viscous and Coulomb coefficients' worst relative error against the device's."""
    law = TRUTH.config.actuation.friction
    return (np.abs(fit.x[-6:-3] / np.asarray(law.viscous) - 1).max(),
            np.abs(fit.x[-3:] / np.asarray(law.coulomb) - 1).max())


@pytest.fixture(scope="module")
def fits():
    log, reference = closed_loop()
    kwargs = dict(structure="general", timing="held", delay=None)
    return estimate(log, PRIOR, **kwargs), estimate(log, PRIOR, reference=reference, **kwargs)


def test_least_squares_is_biased_in_the_loop(fits):
    """And identify says so: the delay it estimates has the torques lead their positions by more
    than 1 ms (result.lead_warning, naming --reference); instrumented, not."""
    least_squares, iv = fits
    assert least_squares.closed_loop == ""
    assert least_squares.delay < -2e-3                       # the simulation has none
    assert friction_error(least_squares)[0] > 0.3
    warning = result.lead_warning(least_squares)
    assert warning.startswith(f"the estimated delay, {1e3 * least_squares.delay:.3f} ms, has the torques logged "
                              "before the positions") and "--reference TRAJ.csv" in warning, warning
    assert warning in result.fit_warnings(least_squares) and result.lead_warning(iv) is None


def test_the_same_loop_without_its_noise_is_not_warned():
    """The loop above without current noise (its first 20 s): least squares estimates the
    simulation's delay (none) within 0.1 ms, and there is no lead warning."""
    fit = estimate(closed_loop(0.0, CLI_DURATION)[0], PRIOR, structure="general", timing="held", delay=None)
    assert abs(fit.delay) < 1e-4 and result.lead_warning(fit) is None, fit.delay


def test_instrumental_variables_find_the_simulation(fits):
    _, iv = fits
    assert iv.closed_loop.startswith("closed loop: the log follows the reference")
    assert abs(iv.delay) < 1e-3
    viscous, coulomb = friction_error(iv)
    assert viscous < 0.2 and coulomb < 0.02
    assert held_out_error(iv) < 0.02                         # the log's predicted uncertainty: 1.9 % (joint 1)
    assert (iv.gains == 1).all()                             # no gain corrected: the device's are 1
    assert not np.any(iv.gains_estimated[1])                 # nor estimated: instrumented, they are biased


def test_a_reference_the_log_does_not_follow_is_refused():
    log, (t, theta) = closed_loop()
    with pytest.raises(LogError, match="does not follow the reference") as error:
        estimate(log, PRIOR, reference=(t, theta[::-1]))
    assert error.value.argument == "reference"


@pytest.mark.parametrize("reference", [(np.arange(3.0), np.zeros((3, 3))), "traj.csv", (np.arange(5.0), np.zeros(5)),
                                       (np.arange(3.0), np.full((3, 3), np.nan))])
def test_bad_references_are_refused(reference):
    log = closed_loop()[0]
    with pytest.raises(InvalidInputError) as error:
        estimate(log, PRIOR, reference=reference)
    assert isinstance(error.value, (ValueError, PhantomPinError)) and error.value.argument == "reference"


def test_identify_reference_on_the_command_line(tmp_path, capsys):
    """`identify LOG --reference TRAJ.csv` on the closed loop's first CLI_DURATION s: the closed
    loop said in the printed report, the torque gains kept at 1 (said in that line); the log and
    its reference in OpenHaptics' convention give the same model; a reference the log does not
    follow or no trajectory file refused in one line naming --reference, exit 2, nothing written."""
    from phantom_pin.cli import main
    from phantom_pin.identification.data import io

    whole, _ = closed_loop()
    n = int(round(CLI_DURATION * 1000)) + 1        # the plumbing, not the accuracy: the first 20 s
    log = io.Log(whole.t[:n], whole.theta[:n], whole.tau[:n])
    t_, theta_, dtheta, ddtheta = (x[:n] for x in sum_of_sines(DURATION, AMPLITUDE, SEED))
    io.write_log(tmp_path / "log.csv", log.t, log.theta, log.tau)
    table = np.column_stack([t_, theta_, dtheta, ddtheta, np.zeros_like(theta_)])
    io.write_csv(tmp_path / "traj.csv", io.TRAJECTORY_COLUMNS, table)
    lengths = [f"--set=kinematics.{k}={v!r}" for k, v in dataclasses.asdict(TRUTH.config.kinematics).items()]
    common = ["-q", *lengths, "identify", str(tmp_path / "log.csv")]
    code = main([*common, "--reference", str(tmp_path / "traj.csv"), "-o", str(tmp_path / "id.yaml")])
    out, err = capsys.readouterr()
    assert code == 0, err
    assert "closed loop: the log follows the reference given" in out and (tmp_path / "id.yaml").is_file()
    assert "the torque gains not estimated" in out
    assert "torque gains: not estimated (a closed loop given its reference" in out     # not --fixed-gains
    # the same in OpenHaptics' convention, as `excite --convention openhaptics` writes the reference
    oh = conventions.openhaptics_from_theta
    io.write_csv(tmp_path / "log_oh.csv", io.LOG_COLUMNS,
                 np.column_stack([log.t, oh(log.theta), conventions.openhaptics_torque_from_tau(log.tau)]))
    io.write_csv(tmp_path / "traj_oh.csv", io.TRAJECTORY_COLUMNS,
                 np.column_stack([t_, oh(theta_), oh(dtheta), oh(ddtheta), np.zeros_like(theta_)]))
    code, out_oh, err = run_cli("-q", *lengths, "identify", tmp_path / "log_oh.csv", "--convention", "openhaptics",
                                "--reference", tmp_path / "traj_oh.csv", "-o", tmp_path / "id_oh.yaml")
    assert code == 0, err
    assert "closed loop: the log follows the reference given" in out_oh
    written, written_oh = read_overrides(tmp_path / "id.yaml"), read_overrides(tmp_path / "id_oh.yaml")
    assert written.keys() == written_oh.keys()
    assert all(np.isclose(written_oh[k], v, rtol=1e-6, atol=1e-9) if isinstance(v, float) else written_oh[k] == v
               for k, v in written.items())       # one log in two conventions: one model (rounding apart)
    # the reference played backwards: a trajectory file of its own, which the log does not follow
    reversed_ = np.column_stack([t_, theta_[::-1], -dtheta[::-1], ddtheta[::-1], np.zeros_like(theta_)])
    io.write_csv(tmp_path / "backwards.csv", io.TRAJECTORY_COLUMNS, reversed_)
    for reference in ("backwards.csv", "missing.csv"):
        code = main([*common, "--reference", str(tmp_path / reference), "-o", str(tmp_path / "no.yaml")])
        err = capsys.readouterr().err
        assert code == 2 and err.count("\n") == 1 and "--reference" in err, err
        assert not (tmp_path / "no.yaml").exists()


def test_with_the_reference_given_no_warning_asks_for_it(fits):
    """Mutant 52. The lead warning tells the user to give --reference (instrumental variables);
    with it given (the instrumented fit: its delay estimated on the instruments, which the loop's
    noise does not drive), no delay it finds, even a 4 ms lead, prints that warning, nor any
    warning naming --reference."""
    _, iv = fits
    assert iv.closed_loop and iv.delay_estimated
    leading = dataclasses.replace(iv, delay=-4e-3)
    assert result.lead_warning(leading) is None
    assert not [w for w in result.fit_warnings(leading) if "--reference" in w]
