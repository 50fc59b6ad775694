"""What the tests share besides fixtures: the default model's configuration and files, frame
poses by Pinocchio, relative errors, and the browser helpers: render an HTML file in headless
chromium, project a world point to its pixel with meshcat's camera (75 degrees vertical field of
view, looking at the world origin, z up, from viewer.CAMERA_POSITION)."""

import json
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pinocchio as pin
from PIL import Image

from phantom_pin import config
from phantom_pin.viewer import CAMERA_POSITION
from phantom_pin.viewer.screenshot import chromium_command

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
    assert shutil.which("chromium"), "Debian's chromium is required (.ci/run installs it: apt-get install chromium)"
    command = chromium_command(html, png, WIDTH, HEIGHT, png.parent / f"{png.stem}-profile")
    subprocess.run(command, check=True, capture_output=True, timeout=120)
    return np.asarray(Image.open(png).convert("RGB")).astype(int)


def browse(html: Path, png: Path) -> tuple[np.ndarray, list[str], list[str]]:
    """Screenshot ``html`` as render() does, with chromium's log and network log: the image, the
    page's console messages (chromium's "CONSOLE" lines) and the URLs of the requests the page
    started (its network log's URL_REQUEST_START_JOB events from the file:// page; chromium's
    own background requests, which it starts from no page, are not the page's)."""
    assert shutil.which("chromium"), "Debian's chromium is required (.ci/run installs it: apt-get install chromium)"
    net_log = png.with_suffix(".netlog.json")
    command = chromium_command(html, png, WIDTH, HEIGHT, png.parent / f"{png.stem}-profile")
    command[1:1] = ["--enable-logging=stderr", "--v=0", f"--log-net-log={net_log}"]
    result = subprocess.run(command, check=True, capture_output=True, text=True, timeout=120)
    console = [line for line in result.stderr.splitlines() if ":CONSOLE" in line]
    log = json.loads(net_log.read_text())
    start = log["constants"]["logEventTypes"]["URL_REQUEST_START_JOB"]
    urls = [event["params"]["url"] for event in log["events"]
            if event["type"] == start and "file://" in event["params"].get("network_isolation_key", "")]
    return np.asarray(Image.open(png).convert("RGB")).astype(int), console, urls


#: SVG coordinates are written with 6 decimals: an affine fit of a curve's points to its numbers
#: leaves less than this share of the span (measured: below 1e-6).
AFFINE_TOLERANCE = 1e-5


def svg_points(page: str, gid: str) -> np.ndarray:
    """The (x, y) vertices (SVG px) of the path in the group ``gid`` (M x y L x y ...) of a page
    drawn by phantom_pin.plots."""
    group = re.search(rf'<g id="{re.escape(gid)}">\s*<path d="([^"]*)"', page)
    assert group is not None, gid
    return np.array([float(v) for v in re.findall(r"-?\d+(?:\.\d+)?", group.group(1))]).reshape(-1, 2)


def affine(source: np.ndarray, image: np.ndarray) -> tuple[float, float, float]:
    """(a, b, worst residual / span) of the least-squares fit image = a source + b."""
    a, b = np.polyfit(source, image, 1)
    return a, b, float(np.abs(a * source + b - image).max() / np.ptp(image))


def check_page(html: Path, tmp_path: Path, figures: int) -> str:
    """A phantom_pin.plots page renders in chromium with something drawn, no console line and no
    request, holds no script, ``figures`` SVGs and no address but the SVG namespaces'; its text."""
    image, console, urls = browse(html, tmp_path / "page.png")
    assert console == [] and urls == []
    assert np.count_nonzero(image.min(axis=2) < 200) > 5000  # curves, axes, text: not a blank page
    text = html.read_text()
    # no script, and no address but the SVG namespace's (an identifier, never fetched)
    assert "<script" not in text and text.count("<svg") == figures
    assert set(re.findall(r"https?://[^\s\"']*", text)) <= {"http://www.w3.org/2000/svg", "http://www.w3.org/1999/xlink"}
    return text


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
