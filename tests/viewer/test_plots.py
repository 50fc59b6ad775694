"""simulate --plot and excite --plot: one self-contained HTML page each (phantom_pin.viewer.plots), opened
in headless chromium (helpers.browse): it renders, its plots are not empty, no console message,
no request from the page. The SVG paths carry the numbers: a curve's points are an affine image
of (t, value) of the run's own output (JSON or CSV), and the limit lines sit at the stops and
torque limits read from the model's YAML (not from the code that draws them)."""

import json
import sys

import numpy as np
import pytest
import yaml

from helpers import AFFINE_TOLERANCE, CONFIG_DIR, affine, check_page, svg_points
from phantom_pin.viewer import plots

#: A swing under gravity compensation: theta3 turns up to the coupled stop, and joint 3's gravity
#: torque changes with it (-0.029 N m at 0.4 rad, -0.067 at 2 rad).
SWING = ("simulate", "--theta0", "0", "0.3", "0.4", "--dtheta0", "0.5", "0.5", "4", "--controller", "gravity",
         "--duration", "0.5")
def _limit_value(page: str, gid: str, a: float, b: float) -> float:
    """The data value of a horizontal limit line through the y axis map px = a value + b."""
    y = svg_points(page, gid)[:, 1]
    assert np.ptp(y) == 0, gid  # horizontal
    return (y[0] - b) / a


def _check_page(html, tmp_path) -> str:
    return check_page(html, tmp_path, 3)


def _stops() -> dict:
    return yaml.safe_load((CONFIG_DIR / "joint_limits.yaml").read_text())["stops"]


@pytest.mark.chromium
def test_simulate_plot_draws_the_run_and_its_stops(tmp_path, cli):
    out, html = tmp_path / "run.json", tmp_path / "run.html"
    code, _, err = cli(*SWING, "-o", out, "--plot", html)
    assert code == 0, err
    run = json.loads(out.read_text())
    t, theta, tau = np.array(run["t"]), np.array(run["theta"]), np.array(run["tau"])
    page = _check_page(html, tmp_path)
    assert len(t) == 501 < plots.MAX_POINTS  # every sample drawn
    points = svg_points(page, "theta-joint2")
    assert points.shape == (len(t), 2)
    ax, bx, worst_x = affine(t, points[:, 0])
    ay, by, worst_y = affine(theta[:, 1], points[:, 1])
    assert worst_x < AFFINE_TOLERANCE and worst_y < AFFINE_TOLERANCE and ax > 0 and ay < 0  # SVG's y points down
    stops = _stops()
    for side in ("lower", "upper"):
        assert _limit_value(page, f"theta-limit-joint2-{side}", ay, by) == pytest.approx(stops["joint2"][side],
                                                                                         abs=1e-5)
    # the coupled stops, on theta3 - theta2
    coupling = svg_points(page, "theta-coupling")
    ac, bc, worst = affine(theta[:, 2] - theta[:, 1], coupling[:, 1])
    assert worst < AFFINE_TOLERANCE
    assert _limit_value(page, "theta-limit-coupling-upper", ac, bc) == pytest.approx(
        stops["theta3_minus_theta2_max"], abs=1e-5)
    assert _limit_value(page, "theta-limit-coupling-lower", ac, bc) == pytest.approx(
        -stops["theta2_minus_theta3_max"], abs=1e-5)
    # gravity compensation along the swing: the torques vary, and the saturation's lines are the
    # motors' continuous torque times the ratios (actuation.yaml)
    a, b, worst = affine(tau[:, 2], svg_points(page, "tau-joint3")[:, 1])
    assert worst < AFFINE_TOLERANCE and np.ptp(tau[:, 2]) > 0.01
    actuation = yaml.safe_load((CONFIG_DIR / "actuation.yaml").read_text())
    continuous = actuation["motor"]["max_continuous_torque"] * actuation["transmission_ratio"]["joint3"]
    assert _limit_value(page, "tau-limit-joint3-upper", a, b) == pytest.approx(continuous, rel=1e-4)
    assert _limit_value(page, "tau-limit-joint3-lower", a, b) == pytest.approx(-continuous, rel=1e-4)


@pytest.mark.chromium
def test_excite_plot_draws_the_trajectory_and_its_limits(tmp_path, cli):
    csv, html = tmp_path / "traj.csv", tmp_path / "traj.html"
    code, _, err = cli("excite", "-o", csv, "--plot", html, "--duration", "5", "--rate", "200", "--iterations",
                       "2", "--restarts", "1")
    assert code == 0, err
    table = np.loadtxt(csv, delimiter=",", skiprows=1)
    t, theta, tau = table[:, 0], table[:, 1:4], table[:, 10:13]
    page = _check_page(html, tmp_path)
    for gid, values in (("theta-joint3", theta[:, 2]), ("tau-joint2", tau[:, 1])):
        points = svg_points(page, gid)
        assert points.shape == (len(t), 2)
        assert affine(t, points[:, 0])[2] < AFFINE_TOLERANCE and affine(values, points[:, 1])[2] < AFFINE_TOLERANCE
    a, b, _ = affine(tau[:, 1], svg_points(page, "tau-joint2")[:, 1])
    actuation = yaml.safe_load((CONFIG_DIR / "actuation.yaml").read_text())
    effort = actuation["motor"]["max_continuous_torque"] * actuation["transmission_ratio"]["joint2"]
    assert _limit_value(page, "tau-limit-joint2-upper", a, b) == pytest.approx(effort, rel=1e-4)
    assert _limit_value(page, "tau-limit-joint2-lower", a, b) == pytest.approx(-effort, rel=1e-4)


def test_a_long_series_is_drawn_at_every_kth_sample_and_its_last():
    """5000 samples, at most 2000 points: every 3rd sample (0, 3, ..., 4998) and the last, 4999."""
    t = np.arange(5000) / 1000.0
    values = np.sin(7 * t)
    svg = plots.figure_svg([plots.Panel("p", "y", [plots.Curve(t, values, "y", "long", "#000000")])])
    points = svg_points(svg, "long")
    kept = np.append(np.arange(0, 5000, 3), 4999)
    assert points.shape == (len(kept), 2)
    assert affine(values[kept], points[:, 1])[2] < AFFINE_TOLERANCE


def test_plot_refusals_write_nothing(tmp_path, cli, monkeypatch):
    """A --plot that is no .html, the --output file itself, an existing file without --force, or
    matplotlib missing: one line, exit 2, before the run, nothing written."""
    same = tmp_path / "run.html"
    kept = tmp_path / "kept.html"
    kept.write_text("kept")
    cases = ((tmp_path / "run.png", "name a .html file"), (same, "is the --output file"),
             (kept, "exists; use --force"))
    for plot, message in cases:
        code, _, err = cli(*SWING, "--format", "json", "-o", same, "--plot", plot)
        assert code == 2 and err.count("\n") == 1 and message in err and "--plot" in err, err
    monkeypatch.setitem(sys.modules, "matplotlib", None)  # import matplotlib raises ImportError
    for command in (SWING, ("excite", "--duration", "5")):
        code, _, err = cli(*command, "-o", tmp_path / "x.csv", "--plot", tmp_path / "x.html")
        assert code == 2 and err.count("\n") == 1 and "pip install 'phantom_pin[plots]'" in err, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["kept.html"] and kept.read_text() == "kept"
