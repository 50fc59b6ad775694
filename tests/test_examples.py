"""Every script in examples/ runs headless; its figures exist and its printed numbers
pass their independent checks (closed form, energy conservation, the reachable shell,
finite differences, the page rendered in chromium)."""

import importlib.util
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from conftest import dark, frame_pose, patch, render
from phantom_pin import load

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


def run(script: str, out: Path, *argv: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, str(EXAMPLES / script), "--out", str(out), *argv],
                          capture_output=True, text=True, timeout=300)


def number(pattern: str, text: str) -> float:
    match = re.search(pattern, text)
    assert match, f"{pattern!r} not in the output:\n{text}"
    return float(match.group(1))


def figure(path: Path) -> None:
    with Image.open(path) as image:
        assert image.format == "PNG" and image.width >= 600 and image.height >= 400


def test_gravity_compensation_matches_the_closed_form(tmp_path):
    result = run("gravity_compensation.py", tmp_path)
    assert result.returncode == 0, result.stderr
    figure(tmp_path / "gravity_compensation.png")
    assert number(r"max difference (\S+) N m", result.stdout) < 1e-9


def test_simulate_conserves_energy(tmp_path):
    result = run("simulate.py", tmp_path)
    assert result.returncode == 0, result.stderr
    figure(tmp_path / "simulate.png")
    assert number(r"kinetic energy peaks at (\S+) J", result.stdout) > 1e-2  # it does swing
    assert number(r"max \|E\(t\) - E\(0\)\| = (\S+) J", result.stdout) < 1e-8


def test_workspace_stays_inside_the_reachable_shell(tmp_path):
    result = run("workspace.py", tmp_path, "--samples", "15")
    assert result.returncode == 0, result.stderr
    figure(tmp_path / "workspace.png")
    assert re.search(r": 3375 of 3375", result.stdout), result.stdout


def test_trajectory_torques_track_the_path(tmp_path):
    result = run("trajectory_torques.py", tmp_path)
    assert result.returncode == 0, result.stderr
    figure(tmp_path / "trajectory_torques.png")
    assert number(r"tracking error max (\S+) m", result.stdout) < 1e-9
    # 301 samples over 0.6 s: second-order differences are good to about 1e-3 rad/s
    assert number(r"finite differences of theta\(t\): max (\S+) rad/s", result.stdout) < 1e-3


def test_visualize_page_shows_the_arm_on_its_sweep(tmp_path):
    """The page renders the arm, with the tip ball on one of the sweep's postures (the
    browser's clock decides which; test_viewer checks the timing of animations)."""
    result = run("visualize.py", tmp_path)
    assert result.returncode == 0, result.stderr
    image = render(tmp_path / "visualize.html", tmp_path / "visualize.png")
    assert np.count_nonzero(np.ptp(image[40:], axis=2) < 30) > 3000
    spec = importlib.util.spec_from_file_location("visualize", EXAMPLES / "visualize.py")
    sys.path.insert(0, str(EXAMPLES))
    try:
        example = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(example)
    finally:
        sys.path.remove(str(EXAMPLES))
    robot = load()
    _, postures = example.sweep(robot.model.lowerPositionLimit, robot.model.upperPositionLimit)
    assert any(dark(patch(image, frame_pose(robot.model, theta, "tip").translation)) for theta in postures)


@pytest.mark.parametrize("script", ["gravity_compensation.py", "simulate.py", "workspace.py",
                                    "trajectory_torques.py", "visualize.py"])
def test_existing_output_is_kept_without_force(tmp_path, script):
    name = script.replace(".py", ".html" if script == "visualize.py" else ".png")
    (tmp_path / name).write_text("keep")
    result = run(script, tmp_path)
    assert result.returncode == 2 and "--force" in result.stderr and result.stderr.count("\n") == 1
    assert (tmp_path / name).read_text() == "keep"
