"""What the tests share besides fixtures: the default model's configuration and files, frame
poses by Pinocchio, relative errors, and the browser helpers: render an HTML file in headless
chromium, project a world point to its pixel with meshcat's camera (75 degrees vertical field of
view, looking at the world origin, z up, from viewer.CAMERA_POSITION)."""

import shutil
import subprocess
from pathlib import Path

import numpy as np
import pinocchio as pin
from PIL import Image

from phantom_pin import config
from phantom_pin.viewer import CAMERA_POSITION

N_STATES = 1000
#: The default model's configuration (premium_1_5) and the report's numbers it holds.
CONFIG = config.read()
REPORT = CONFIG.report
#: Its configuration folder and committed generated files.
MODEL = config.MODELS["premium_1_5"]
CONFIG_DIR, URDF_PATH, SRDF_PATH, MJCF_PATH, SCENE_PATH = MODEL.config, MODEL.urdf, MODEL.srdf, MODEL.mjcf, MODEL.scene


def frame_pose(model: pin.Model, theta: np.ndarray, name: str) -> pin.SE3:
    """World pose of the frame ``name`` at theta (rad), by Pinocchio's forward kinematics."""
    data = model.createData()
    pin.framesForwardKinematics(model, data, np.asarray(theta, dtype=float))
    return pin.SE3(data.oMf[model.getFrameId(name)])  # a copy, independent of data


def relative_error(actual: np.ndarray, expected: np.ndarray) -> float:
    """max |actual - expected| / max |expected| over the whole array."""
    return float(np.abs(actual - expected).max() / np.abs(expected).max())


WIDTH, HEIGHT, FOV = 800, 600, 75.0
RESTING, RAISED = np.array([0.0, -0.25, -0.35]), np.array([-1.0, 1.0, 1.1])
#: Pixels around a projected point searched for its colour (the projection is exact;
#: this allows for rasterisation and antialiasing).
WINDOW = 4


def render(html: Path, png: Path) -> np.ndarray:
    """Screenshot ``html`` in headless chromium (WebGL through SwiftShader): (H, W, 3) ints."""
    chromium = shutil.which("chromium")
    assert chromium, "Debian's chromium is required (.ci/run installs it: apt-get install chromium)"
    profile = png.parent / f"{png.stem}-profile"
    command = [chromium, "--headless", "--no-sandbox", "--use-gl=swiftshader",
               "--enable-unsafe-swiftshader", f"--window-size={WIDTH},{HEIGHT}",
               "--disable-background-networking", "--disable-component-update", "--disable-sync",
               "--no-first-run", "--disable-quic", f"--user-data-dir={profile}",
               "--virtual-time-budget=2000", f"--screenshot={png}", html.resolve().as_uri()]
    subprocess.run(command, check=True, capture_output=True, timeout=120)
    return np.asarray(Image.open(png).convert("RGB")).astype(int)


def project(point: np.ndarray) -> tuple[int, int]:
    """Pixel (column, row) of a world point (m) seen from CAMERA_POSITION."""
    eye = CAMERA_POSITION
    forward = -eye / np.linalg.norm(eye)
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    d = point - eye
    depth, half = d @ forward, np.tan(np.radians(FOV) / 2)
    return (round(WIDTH / 2 * (1 + d @ right / (depth * half * WIDTH / HEIGHT))),
            round(HEIGHT / 2 * (1 - d @ up / (depth * half))))


def patch(image: np.ndarray, point: np.ndarray) -> np.ndarray:
    column, row = project(point)
    assert 0 <= column < WIDTH and 0 <= row < HEIGHT, "the point must be in view"
    return image[row - WINDOW:row + WINDOW + 1, column - WINDOW:column + WINDOW + 1].reshape(-1, 3)


def dark(pixels: np.ndarray) -> bool:
    """The tip ball is black; the background there is a saturated blue gradient."""
    return bool(np.any((pixels.max(axis=1) < 90) & (np.ptp(pixels, axis=1) < 25)))


def light_grey(pixels: np.ndarray) -> bool:
    """The arm's tubes are light grey (0.75); the background is saturated, the base darker."""
    return bool(np.any((pixels.min(axis=1) > 120) & (np.ptp(pixels, axis=1) < 25)))


def red(pixels: np.ndarray) -> bool:
    return bool(np.any((pixels[:, 0] > 140) & (pixels[:, 1] < 90) & (pixels[:, 2] < 90)))
