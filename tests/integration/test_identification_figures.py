"""benchmarks/identification_figures.py --quick on its clean row: the CAD-built Premium 1.5,
identified on the shipped model from excite's trajectory (20 s, instantaneous torques, no
noise), judged against bounds from elsewhere: the prior's error recomputed here, and the
accuracy tests/identification/structure/test_structures.py documents for a NOISY log of a device of the
same kind (0.068 % on 500 states, friction within 1.3 %): a clean log must do at least as well."""

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from phantom_pin import Phantom, describe
from phantom_pin.config.sampling import random_states

#: Runs a script of examples/ or benchmarks/ in a fresh interpreter (pytest -m "not slow": the quick loop).
pytestmark = pytest.mark.slow

ROOT = Path(__file__).resolve().parents[2]
SCRIPT = ROOT / "benchmarks" / "identification_figures.py"
CLEAN = "clean, instantaneous torques, --torque-timing sampled"


def run(*argv):
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), *filter(None, [os.environ.get("PYTHONPATH")])])}
    return subprocess.run([sys.executable, str(SCRIPT), *argv], capture_output=True, text=True, timeout=300, env=env)


def percent(cell):
    return float(cell.split()[0]) / 100


def test_the_quick_figures_meet_the_documented_accuracy_and_keep_an_existing_file(tmp_path):
    output = tmp_path / "figures.md"
    result = run("--quick", "--conditions", "clean", "-o", str(output))
    assert result.returncode == 0, result.stderr
    assert output.read_text() == result.stdout and "cad, excite, clean" in result.stderr     # progress on stderr
    rows = {cells[2]: cells for cells in (line.split(" | ") for line in result.stdout.splitlines()
                                          if line.startswith("| CAD Premium 1.5"))}
    truth = describe("premium_1_5_cad")
    lengths = truth.config.kinematics
    prior = Phantom(describe("premium_1_5", overrides={"l1": lengths.l1, "l2": lengths.l2, "l3": lengths.l3}))
    states = random_states(prior.config.limits, 500, 7)
    true = Phantom(truth).inverse_dynamics(*states)
    expected = np.sqrt(((prior.inverse_dynamics(*states) - true) ** 2).mean(axis=0) / (true**2).mean(axis=0)).max()
    prior_row = rows["the prior (the configuration identified on)"]
    assert abs(percent(prior_row[4]) - expected) < 1e-5              # printed to 0.001 %: 19 % measured
    clean = rows[CLEAN]
    assert percent(clean[3]) < 1e-3 and percent(clean[4]) < 1e-3     # 0.015 % and 0.019 % measured
    viscous, coulomb = (float(v) / 100 for v in clean[5].rstrip(" %").split(" / "))
    assert abs(viscous) < 0.013 and abs(coulomb) < 0.013             # +0.3 % and -0.1 % measured
    assert clean[9].strip() == "accepted" and clean[10].strip() == "yes"
    assert 0 < float(clean[11].rstrip(" |")) <= 1          # within the printed 2 sigma (0.65 measured at 60 s)
    again = run("--quick", "--conditions", "clean", "-o", str(output))
    assert again.returncode == 2 and "--output: " in again.stderr and "use --force" in again.stderr
    assert output.read_text() == result.stdout


def test_the_rest_postures_part_runs_alone_within_the_issues_goal():
    """--parts rest on the CAD, one seed: its table alone (no main table), the 12 postures
    determine the 4 gravity directions, and the written gravity is within the issue's 1 %
    (0.38 % measured) and within 3 times what static predicts (0.9)."""
    result = run("--parts", "rest", "--setups", "cad", "--rest-seeds", "1")
    assert result.returncode == 0, result.stderr
    assert "| trajectory | condition |" not in result.stdout
    rows = [line.split(" | ") for line in result.stdout.splitlines() if line.startswith("| CAD Premium 1.5")]
    assert len(rows) == 1
    row = rows[0]
    assert row[3].startswith("4 of 4 directions") and row[8].strip() == "yes |"
    assert percent(row[5]) < 0.01 and float(row[6]) < 3
