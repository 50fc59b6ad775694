"""Regenerate the pictures under docs/pictures/: each model (phantom_pin.models()) in its
report's zero configuration as the project's own viewer draws it, and a figure of the frames
(base_link, the report's frame s and OpenHaptics' frame, on the Touch), each rendered by headless
chromium (phantom_pin.viewer.screenshot). Needs Debian's chromium and pillow (the `plots` extra).

    python docs/pictures.py --force                  # rewrite the committed pictures
    python docs/pictures.py --output /tmp/pictures   # somewhere else

Frames (m): the viewer's world is base_link (REP-103: x forward, y left, z up, origin at the
shoulder); frame s is the report's (x left, y up, z forward, origin at the zero posture's tip);
OpenHaptics' frame has frame s's axes and its origin at phantom_pin.interfaces.conventions.openhaptics_origin
(an ESTIMATE for the Touch: phantom_pin/interfaces/conventions.py).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

import meshcat.geometry as mg
import numpy as np
import pinocchio as pin
from PIL import Image, ImageDraw, ImageFont

from phantom_pin import config, describe, load, models
from phantom_pin._validation import output_path
from phantom_pin.exceptions import PhantomPinError
from phantom_pin.interfaces.conventions import openhaptics_origin
from phantom_pin.viewer import CAMERA_POSITION, Viewer
from phantom_pin.viewer.screenshot import screenshot

FOLDER = Path(__file__).resolve().parent / "pictures"
WIDTH, HEIGHT = 800, 600
#: The frames' axes: length and radius (m), and the colour of x, y, z; each origin's marker.
AXIS_LENGTH, AXIS_RADIUS, MARKER_RADIUS = 0.06, 0.0022, 0.007
AXIS_COLOURS = (0xD02020, 0x20A020, 0x2040D0)
#: The frames figure's posture (rad): the upper arm raised and the forearm forward, so that the
#: tip leaves frame s's origin (the zero posture's tip) in view.
FRAMES_THETA = (0.0, 0.5, 0.9)
FRAMES = (("base_link", 0x202020, "base_link (REP-103): x forward, y left, z up; origin at the shoulder"),
          ("report_s", 0xE08000,
           "frame s (the report's): x left (the user's right), y up, z forward (to the user); origin: the zero "
           "posture's tip"),
          ("openhaptics", 0xB020B0, "OpenHaptics' frame: frame s's axes; origin ESTIMATED (drivers.py)"))


def _camera(name: str) -> np.ndarray:
    """The viewer's camera position (m, base_link) scaled to the model's arm: the default frames
    the Premium 1.5 (l1 + l2); a smaller arm is seen from as much nearer."""
    k, default = config.read(name).kinematics, config.read(config.DEFAULT).kinematics
    return CAMERA_POSITION * (k.l1 + k.l2) / (default.l1 + default.l2)


def _render(viewer: Viewer, png: Path, force: bool) -> Path:
    """Screenshot the viewer's exported page into ``png``, without meshcat's grid and world axes
    (the world is base_link, which the frames figure draws itself)."""
    for node in ("/Grid", "/Axes"):
        viewer.scene[node].set_property("visible", False)
    with tempfile.TemporaryDirectory() as folder:
        page = viewer.export_html(Path(folder) / "scene.html")
        return screenshot(page, png, width=WIDTH, height=HEIGHT, force=force)


def model_picture(name: str, png: Path, force: bool = False) -> Path:
    """``name`` in its SRDF posture ``zero`` (the report's zero configuration), written to ``png``."""
    with Viewer(load(describe(name))) as viewer:
        viewer.set_camera(_camera(name))
        viewer.show(config.read(name).limits.postures["zero"])
        return _render(viewer, png, force)


def frame_poses(name: str = "touch") -> dict[str, pin.SE3]:
    """The figure's frames in base_link (m): base_link itself, report_s (the URDF's fixed frame)
    and OpenHaptics' (frame s's axes, its origin at -openhaptics_origin in frame s)."""
    robot = load(describe(name))
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, robot.q0)
    s = pin.SE3(data.oMf[robot.model.getFrameId("report_s")])
    return {"base_link": pin.SE3.Identity(), "report_s": s,
            "openhaptics": s * pin.SE3(np.eye(3), -openhaptics_origin(config.read(name)))}


def _draw_frame(viewer: Viewer, label: str, pose: pin.SE3, marker: int) -> None:
    """Three arrows (x, y, z: AXIS_COLOURS) from ``pose``'s origin and a sphere of colour ``marker``."""
    node = viewer.scene[f"frames/{label}"]
    # meshcat's cylinder lies along its local y: turn it onto x, keep it on y, turn it onto z
    turns = (pin.utils.rotate("z", -np.pi / 2), np.eye(3), pin.utils.rotate("x", np.pi / 2))
    for axis, (turn, colour) in enumerate(zip(turns, AXIS_COLOURS)):
        node[f"axis{axis}"].set_object(mg.Cylinder(AXIS_LENGTH, AXIS_RADIUS), mg.MeshLambertMaterial(color=colour))
        offset = pin.SE3(turn, turn @ np.array([0.0, AXIS_LENGTH / 2, 0.0]))
        node[f"axis{axis}"].set_transform((pose * offset).homogeneous)
    node["origin"].set_object(mg.Sphere(MARKER_RADIUS), mg.MeshLambertMaterial(color=marker))
    node["origin"].set_transform(pose.homogeneous)


def _legend(png: Path) -> None:
    """Write the legend (each frame's marker colour and axes, the axes' colours) onto ``png``."""
    image = Image.open(png).convert("RGB")
    draw, font = ImageDraw.Draw(image), ImageFont.load_default(size=14)
    lines = [(marker, text) for _, marker, text in FRAMES] + [(None, "axes: x red, y green, z blue")]
    draw.rectangle((8, 8, WIDTH - 8, 16 + 20 * len(lines)), fill=(255, 255, 255))
    for row, (marker, text) in enumerate(lines):
        y = 14 + 20 * row
        if marker is not None:
            draw.ellipse((16, y + 2, 28, y + 14), fill=((marker >> 16) & 255, (marker >> 8) & 255, marker & 255))
        draw.text((36, y), text, fill=(0, 0, 0), font=font)
    image.save(png)


def frames_picture(png: Path, force: bool = False, name: str = "touch") -> Path:
    """The Touch at FRAMES_THETA with base_link, frame s and OpenHaptics' frame drawn, and a
    legend, written to ``png``."""
    output_path(png, force, "png")  # before rendering: nothing is written on a refusal
    poses = frame_poses(name)
    with Viewer(load(describe(name))) as viewer:
        viewer.set_camera(_camera(name))
        viewer.show(FRAMES_THETA)
        for label, marker, _ in FRAMES:
            _draw_frame(viewer, label, poses[label], marker)
        with tempfile.TemporaryDirectory() as folder:
            shot = _render(viewer, Path(folder) / "frames.png", force=False)
            _legend(shot)
            Image.open(shot).save(png)
    return png


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--output", type=Path, default=FOLDER, help="folder of the PNGs (default docs/pictures)")
    parser.add_argument("--force", action="store_true", help="overwrite existing pictures")
    options = parser.parse_args(argv)
    try:
        if not options.output.is_dir():
            raise PhantomPinError(f"--output: {options.output} is not a folder")
        targets = [options.output / f"{name}.png" for name in models()] + [options.output / "frames.png"]
        for target in targets:  # every refusal before the first picture
            output_path(target, options.force, "--output", "--force")
        for name, target in zip(models(), targets):
            print(f"wrote {model_picture(name, target, options.force)}")
        print(f"wrote {frames_picture(targets[-1], options.force)}")
    except PhantomPinError as error:
        print(f"pictures.py: {error}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
