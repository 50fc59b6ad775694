"""The device examples run headless; their figures exist and their printed numbers pass
independent checks (Hooke's law at the wall, the passivity bound, the closed-form gravity,
the motors' continuous rating)."""

import re
import subprocess
import sys
from pathlib import Path

import pytest
from PIL import Image

#: Runs a script of examples/ or benchmarks/ in a fresh interpreter (pytest -m "not slow": the quick loop).
pytestmark = pytest.mark.slow

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def run(script: str, out: Path, *argv: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, str(EXAMPLES / script), "--out", str(out), *argv],
                          capture_output=True, text=True, timeout=300)


def numbers(pattern: str, text: str) -> list[tuple[float, ...]]:
    found = [tuple(float(x) for x in match) if isinstance(match, tuple) else (float(match),)
             for match in re.findall(pattern, text)]
    assert found, f"{pattern!r} not in the output:\n{text}"
    return found


def figure(path: Path) -> None:
    with Image.open(path) as image:
        assert image.format == "PNG" and image.width >= 600 and image.height >= 400


def test_virtual_wall_settles_by_hookes_law_and_beats_the_passivity_bound(tmp_path):
    result = run("virtual_wall.py", tmp_path, "--rates", "500", "1000")
    assert result.returncode == 0, result.stderr
    figure(tmp_path / "virtual_wall.png")
    out = result.stdout
    # the 1000 N/m wall at 1 kHz settles where K x = the 1 N push (x = 1 mm); 2000 N/m buzzes
    (settled, hooke), = numbers(r"K = 1000 N/m: stable; last 0.1 s: penetration (\S+) mm \(F/K = (\S+) mm\)", out)
    assert hooke == 1.0 and abs(settled - hooke) < 0.02                   # mm (measured 0.996)
    assert "K = 2000 N/m: unstable" in out
    sweep = numbers(r"rate (\S+) Hz: highest stable K = (\S+) N/m \(simulate\), (\S+) N/m \(mujoco\); "
                    r"passivity bound (\S+) N/m \(viscous\)", out)
    assert [rate for rate, _, _, _ in sweep] == [500, 1000]
    # the two plants' maps agree (measured: equal on the grid at 250-2000 Hz)
    assert all(ours == mujoco for _, ours, mujoco, _ in sweep)
    sweep = [(rate, ours, bound) for rate, ours, _, bound in sweep]
    # passivity is sufficient: every passive wall is stable, so the measured limit is above it
    assert all(measured > bound for _, measured, bound in sweep)
    assert sweep[1][1] > sweep[0][1]                                      # faster sampling, stiffer wall
    assert [bound for _, _, bound in sweep] == pytest.approx([10.79, 21.59], rel=1e-3)  # 2 b_n / T


def test_gravity_currents_match_the_closed_form_and_stay_below_the_rating(tmp_path):
    result = run("gravity_currents.py", tmp_path, "--samples", "41")
    assert result.returncode == 0, result.stderr
    figure(tmp_path / "gravity_currents.png")
    out = result.stdout
    assert numbers(r"max difference (\S+) N m", out)[0][0] < 1e-12
    shares = numbers(r"worst holding current (\S+) A = (\S+)% of the continuous 1.24 A", out)
    assert len(shares) == 2 and all(0 < share < 100 for _, share in shares)
    assert all(current / 1.24 * 100 == pytest.approx(share, abs=0.05) for current, share in shares)
    assert numbers(r"min (\S+) N", out)[0][0] > 1.0                       # N of downward force left


@pytest.mark.parametrize("script", ["virtual_wall.py", "gravity_currents.py"])
def test_existing_output_is_kept_without_force(tmp_path, script):
    name = script.replace(".py", ".png")
    (tmp_path / name).write_text("keep")
    result = run(script, tmp_path)
    assert result.returncode == 2 and "--force" in result.stderr and result.stderr.count("\n") == 1
    assert (tmp_path / name).read_text() == "keep"
