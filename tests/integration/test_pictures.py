"""docs/pictures.py: it runs and writes a model's picture and the frames figure, none of them
blank (not equal to the committed ones, one per model and the frames figure, pixel for pixel:
SwiftShader's output may change with chromium). Counts of pixels below were measured on
2026-11-27's renders (8 600-9 700 grey arm pixels per model; the frames figure's axes 700 red
and 540 green, markers 290 magenta and 240 orange); the thresholds are a third of those or less."""

import importlib.util
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from phantom_pin import models

ROOT = Path(__file__).resolve().parents[2]
SCRIPT = ROOT / "docs" / "pictures.py"
NAMES = [*models(), "frames"]


def _script():
    spec = importlib.util.spec_from_file_location("pictures", SCRIPT)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _counts(image: np.ndarray) -> dict[str, int]:
    """Pixels (H, W, 3 ints) of the arm's unsaturated grey and of the frames' colours."""
    r, g, b = image[..., 0], image[..., 1], image[..., 2]
    return {"grey": int(((np.ptp(image, axis=2) < 30) & (image.max(axis=2) > 60)).sum()),
            "red": int(((r > 150) & (g < 80) & (b < 80)).sum()), "green": int(((g > 120) & (r < 90) & (b < 90)).sum()),
            "magenta": int(((r > 130) & (b > 130) & (g < 80)).sum()),
            "orange": int(((r > 180) & (g > 90) & (g < 170) & (b < 60)).sum())}


def test_the_committed_pictures_are_the_ones_the_script_writes():
    assert sorted(p.stem for p in (ROOT / "docs" / "pictures").glob("*.png")) == sorted(NAMES)


@pytest.mark.slow
@pytest.mark.chromium
def test_the_script_renders_a_model_and_the_frames(tmp_path, capsys, monkeypatch):
    """The script's loop over models() run on the Touch alone (the model with a stylus; each render
    is a chromium run of 1-2 s of CPU): its picture and the frames figure."""
    pictures = _script()
    monkeypatch.setattr(pictures, "models", lambda: ("touch",))
    assert pictures.main(["--output", str(tmp_path)]) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["frames.png", "touch.png"]
    for name in ("touch", "frames"):
        image = np.asarray(Image.open(tmp_path / f"{name}.png").convert("RGB")).astype(int)
        assert image.shape == (pictures.HEIGHT, pictures.WIDTH, 3)
        legend = 110 if name == "frames" else 0  # the frames figure's legend: a white box at the top
        counts = _counts(image[legend:])
        assert counts["grey"] > 3000, (name, counts)  # the arm
        if name == "frames":
            assert counts["red"] > 200 and counts["green"] > 150, counts  # the axes
            assert counts["magenta"] > 80 and counts["orange"] > 80, counts  # OpenHaptics' and s's markers
            assert image[12:100, 12:400].mean() > 200  # the legend
        else:
            assert counts["magenta"] == 0, counts  # no frames drawn
    # a second run refuses in one line, before writing anything, unless --force
    (tmp_path / "touch.png").unlink()
    assert pictures.main(["--output", str(tmp_path)]) == 2
    assert len(capsys.readouterr().err.strip().splitlines()) == 1 and not (tmp_path / "touch.png").exists()
