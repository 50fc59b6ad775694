"""identify --report: one self-contained HTML page of the fit (phantom_pin.identification.verdict.page),
written with the overlay or not at all, opened in headless chromium (helpers.browse): it renders,
its plots are not empty, no console message, no request from the page. Its curves carry the
numbers: the measured torques are the log's own (filtered: within a share of their RMS), the
friction law drawn is the one the overlay writes (read back from the YAML, not from the code that
draws it)."""

import re

import numpy as np
import pytest

from helpers import AFFINE_TOLERANCE, affine, check_page, svg_points
from phantom_pin import Phantom
from phantom_pin.config import read_overrides
from phantom_pin.identification import identify
from phantom_pin.identification.data import io

#: The filtered torques against the log's at the same rows, where the joint's equation is fitted:
#: the 20 Hz filter and the held timing's half sample (measured: 0.75-1.3 % of the torque RMS on
#: the three joints; 1.3-2.9 % with the samples near rest, whose stick corrections the filter
#: removes; another joint's torque: 130-230 %).
FILTERED_SHARE = 0.03


def _markers(page: str, gid: str) -> np.ndarray:
    """The (x, y) of the points (SVG `use` elements) in the group ``gid``: a scatter."""
    group = re.search(rf'<g id="{re.escape(gid)}">(.*?)</g>', page, re.S)
    assert group is not None, gid
    return np.array([[float(x), float(y)] for x, y in re.findall(r'<use [^>]*x="([-\d.]+)" y="([-\d.]+)"',
                                                                  group.group(1))])


@pytest.fixture(scope="module")
def identified(tmp_path_factory):
    """excite (5 s) -> simulate --trajectory -> identify --report: the folder."""
    from phantom_pin.cli import main

    folder = tmp_path_factory.mktemp("report")
    assert main(["excite", "-o", str(folder / "traj.csv"), "--duration", "5", "--iterations", "10",
                 "--restarts", "1", "--quiet"]) == 0
    assert main(["simulate", "--trajectory", str(folder / "traj.csv"), "--format", "csv", "-o",
                 str(folder / "log.csv"), "--quiet"]) == 0
    assert main(["identify", str(folder / "log.csv"), "-o", str(folder / "id.yaml"), "--report",
                 str(folder / "id.html"), "--quiet"]) == 0
    return folder


@pytest.mark.chromium
def test_the_report_renders_offline_with_its_figures(identified, tmp_path):
    text = check_page(identified / "id.html", tmp_path, 2)
    for heading in ("Measured and predicted joint torques", "The held-out check", "against the rate",
                    "Each parameter with its uncertainty", "Timing and torque gains", "Warnings"):
        assert heading in text, heading
    for j in (1, 2, 3):
        assert len(svg_points(text, f"tau-measured-joint{j}")) > 100
        assert len(svg_points(text, f"tau-predicted-joint{j}")) > 50
        assert len(_markers(text, f"friction-measured-joint{j}")) > 100
        assert len(_markers(text, f"residual-joint{j}")) > 100


def test_the_report_draws_the_logs_torques_and_the_written_friction(identified):
    """The measured curve of joint 2 is an affine image of (t, the filtered torque), and that
    torque is the log's at those rows; the friction law of joint 1 drawn is viscous v + coulomb
    sign(v) with the overlay's own two numbers."""
    text = (identified / "id.html").read_text()
    log = io.read_log(identified / "log.csv")
    t, tau = log.t, log.tau
    result = identify(log, Phantom(), delay=None)    # the command's defaults (the delay estimated)
    curves = result.fit.curves
    points = svg_points(text, "tau-measured-joint2")
    assert points.shape == (len(curves.t), 2)
    ax, _, worst_x = affine(curves.t, points[:, 0])
    ay, _, worst_y = affine(curves.measured[:, 1], points[:, 1])
    assert worst_x < AFFINE_TOLERANCE and worst_y < AFFINE_TOLERANCE and ax > 0 and ay < 0
    rows = np.searchsorted(t, curves.t)
    assert np.allclose(t[rows], curves.t)
    fitted = curves.moving[:, 1]
    error = np.sqrt(np.mean((curves.measured[fitted, 1] - tau[rows[fitted], 1]) ** 2))
    assert error < FILTERED_SHARE * np.sqrt(np.mean(tau[:, 1] ** 2))
    keys = read_overrides(identified / "id.yaml")
    viscous, coulomb = keys["actuation.friction.viscous.joint1"], keys["actuation.friction.coulomb.joint1"]
    v = np.sort(curves.dtheta[curves.moving[:, 0], 0])
    line = svg_points(text, "friction-law-joint1")
    assert line.shape == (len(v), 2)
    _, _, worst_x = affine(v, line[:, 0])
    _, _, worst_y = affine(viscous * v + coulomb * np.sign(v), line[:, 1])
    assert worst_x < AFFINE_TOLERANCE and worst_y < AFFINE_TOLERANCE


def test_a_report_that_cannot_be_written_leaves_no_overlay(identified, tmp_path, cli):
    """--report is checked before any work, and written with the overlay or not at all."""
    out = tmp_path / "id.yaml"
    code, _, err = cli("identify", identified / "log.csv", "-o", out, "--report", tmp_path / "missing" / "id.html")
    assert code == 2 and "--report" in err and not out.exists()
    code, _, err = cli("identify", identified / "log.csv", "-o", out, "--report", tmp_path / "id.txt")
    assert code == 2 and "--report" in err and not out.exists()
    code, _, err = cli("identify", identified / "log.csv", "-o", out, "--report", out)
    assert code == 2 and "--report" in err and not out.exists()
