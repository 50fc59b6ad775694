"""The friction speed threshold chosen from the log (issue 39, 3): the issue's simulated Touch,
the shipped model but for viscous friction on joint 2 (7e-4 N m s/rad) and Coulomb friction on
joint 3 (0.02 N m, near joint 3's torque RMS), identified with the defaults. The reference is the
simulated device's own numbers (its --set) and its own inverse dynamics, not the fit."""

import numpy as np
import pytest

from helpers import excitation_file
from phantom_pin import Phantom, describe
from phantom_pin.config import read_overrides
from phantom_pin.config.sampling import random_states

DEVICE = {"actuation.friction.viscous.joint2": 7e-4, "actuation.friction.coulomb.joint3": 0.02}


@pytest.fixture(scope="module")
def touch_log(tmp_path_factory):
    from phantom_pin.cli import main

    folder = tmp_path_factory.mktemp("touch")
    sets = [a for key, value in DEVICE.items() for a in ("--set", f"{key}={value!r}")]
    # `phantom-pin --model touch excite -o t.csv --restarts 1`'s file (the defaults' too: their
    # first start is the better one on the Touch), from its recorded series (helpers.EXCITATIONS)
    excitation_file(folder / "t.csv", "touch")
    assert main(["-q", "--model", "touch", "simulate", "--trajectory", str(folder / "t.csv"), *sets,
                 "-o", str(folder / "log.csv")]) == 0
    return folder


def _identified(cli, folder, *options):
    code, out, err = cli("-q", "--model", "touch", "identify", folder / "log.csv", "-o", folder / "id.yaml",
                         "--force", *options)
    assert code == 0, err
    return out, err, read_overrides(folder / "id.yaml")


def test_the_threshold_is_chosen_and_the_touch_comes_back_exact(touch_log, cli):
    """With the defaults: a threshold above the sticking samples is chosen and said; the
    friction within 0.5 % (the issue asks 5 %; measured 0.02-0.2 %), no torque gain corrected, no advice to change a
    torque constant, and the rigid body's torques within 0.3 % of the device's at 200 seeded
    states inside the stops (the shipped rigid body is the device's)."""
    out, err, overlay = _identified(cli, touch_log)
    chosen = next(line for line in out.splitlines() if line.startswith("friction speed threshold:"))
    assert "chosen on held-out quarters of the log" in chosen and not chosen.startswith(
        "friction speed threshold: 0.01 rad/s"), chosen
    assert overlay["actuation.friction.viscous.joint2"] == pytest.approx(7e-4, rel=0.005)
    assert overlay["actuation.friction.viscous.joint3"] == pytest.approx(5e-4, rel=0.005)
    assert overlay["actuation.friction.coulomb.joint3"] == pytest.approx(0.02, rel=0.005)
    assert "corrected in the written model" not in out and "torque constant" not in err, err
    identified, device = Phantom(describe("touch", overrides=overlay)), Phantom.from_model("touch")
    theta, dtheta, ddtheta = random_states(device.config.limits, 200, 5)
    truth = device.inverse_dynamics(theta, dtheta, ddtheta)
    error = np.sqrt(((identified.inverse_dynamics(theta, dtheta, ddtheta) - truth) ** 2).mean(0) / (truth**2).mean(0))
    assert (error < 0.003).all(), error


def test_the_old_default_threshold_was_confidently_wrong_on_this_log(touch_log, cli):
    """The same log at the old default, --min-speed 0.01 given: viscous friction off by more
    than 3 % on a joint (4.7 % on joint 3 here; the issue measured 6.7 % and 9.6 % on another
    excitation) where the chosen threshold's is within 0.5 %, so the choice above is what fixed
    it. The log's trajectory is the recorded one (the fixture: `phantom-pin --model touch excite
    -o t.csv --restarts 1` run once, tests/data/excitations.json), not what excite writes today."""
    out, _, _ = _identified(cli, touch_log, "--min-speed", "0.01")
    assert "friction speed threshold: 0.01 rad/s (given" in out
    line = next(line for line in out.splitlines() if line.startswith("friction.viscous estimated per joint"))
    estimates = [float(part.split()[1]) for part in line.split(": ", 1)[1].split(";")[0].split(", ")]
    off = [abs(estimates[j - 1] / v - 1) for j, v in ((2, 7e-4), (3, 5e-4))]
    assert max(off) > 0.03, off
