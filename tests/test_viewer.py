"""The exported HTML rendered by headless chromium (helpers.render), checked against a
pinhole projection of Pinocchio's kinematics (helpers.project)."""

import base64
import json
import re

import numpy as np
import pinocchio as pin
import pytest
import umsgpack

from helpers import RAISED, RESTING, dark, frame_pose, patch, red, render
from phantom_pin.exceptions import InvalidInputError, PhantomPinError
from phantom_pin.viewer import FORCE_SCALE, Viewer


@pytest.fixture(scope="module")
def viewer():
    with Viewer() as v:
        yield v


def tip_frame(viewer: Viewer, theta: np.ndarray) -> tuple[pin.SE3, pin.SE3]:
    """World poses of the frames tip and report_s at theta."""
    model = viewer.robot.model
    return frame_pose(model, theta, "tip"), frame_pose(model, theta, "report_s")


@pytest.mark.chromium
def test_two_postures_are_visible_where_kinematics_put_them(viewer, tmp_path):
    images = {}
    for name, theta in (("resting", RESTING), ("raised", RAISED)):
        viewer.show(theta)
        images[name] = render(viewer.export_html(tmp_path / f"{name}.html"), tmp_path / f"{name}.png")
    tip_resting, tip_raised = (tip_frame(viewer, q)[0].translation for q in (RESTING, RAISED))
    assert dark(patch(images["resting"], tip_resting)) and not dark(patch(images["resting"], tip_raised))
    assert dark(patch(images["raised"], tip_raised)) and not dark(patch(images["raised"], tip_resting))
    for image in images.values():  # the arm's grey links: thousands of unsaturated pixels
        assert np.count_nonzero(np.ptp(image[40:], axis=2) < 30) > 3000
    changed = np.any(np.abs(images["resting"] - images["raised"]) > 30, axis=2)
    assert changed.mean() > 0.01


@pytest.mark.chromium
def test_tip_frame_and_force_arrow_are_drawn(viewer, tmp_path):
    force = np.array([0.0, -2.0, 1.0])  # N, in frame s
    viewer.set_force(force)
    viewer.show(RAISED)
    image = render(viewer.export_html(tmp_path / "force.html"), tmp_path / "force.png")
    viewer.set_force(np.zeros(3))
    tip, s = tip_frame(viewer, RAISED)
    direction = s.rotation @ force
    arrow_middle = tip.translation + 0.5 * FORCE_SCALE * direction
    assert red(patch(image, arrow_middle))
    assert red(patch(image, tip.translation + tip.rotation @ [0.03, 0.0, 0.0]))  # the x axis


@pytest.mark.chromium
def test_animation_plays_in_the_exported_page(viewer, tmp_path):
    """Hold RESTING for 30 s, then move to RAISED: two seconds after loading, the page
    shows RESTING although the scene's own (static) state is the last posture."""
    viewer.animate([0.0, 30.0, 31.0], [RESTING, RESTING, RAISED])
    image = render(viewer.export_html(tmp_path / "animation.html"), tmp_path / "animation.png")
    viewer.show(RESTING)
    tip_resting, tip_raised = (tip_frame(viewer, q)[0].translation for q in (RESTING, RAISED))
    assert dark(patch(image, tip_resting)) and not dark(patch(image, tip_raised))


def test_exported_html_is_self_contained(viewer, tmp_path):
    html = viewer.export_html(tmp_path / "scene.html").read_text()
    assert "<script src" not in html and "http://" not in html.split("<script>")[0]
    assert len(html) > 100_000  # meshcat's viewer code is inlined


def test_bad_input_raises_named_errors(viewer, tmp_path):
    with pytest.raises(InvalidInputError, match="theta"):
        viewer.show([0.0, 0.1])
    with pytest.raises(InvalidInputError, match="theta"):
        viewer.show([0.0, np.nan, 0.0])
    with pytest.raises(InvalidInputError, match="times"):
        viewer.animate([0.0, 0.0], [RESTING, RAISED])
    with pytest.raises(InvalidInputError, match="times, theta"):
        viewer.animate([0.0, 1.0, 2.0], [RESTING, RAISED])
    with pytest.raises(InvalidInputError, match="force"):
        viewer.set_force([1.0, 2.0])
    with pytest.raises(InvalidInputError, match="scale"):
        viewer.set_force([1.0, 0.0, 0.0], scale=-1.0)
    with pytest.raises(InvalidInputError, match="position"):
        viewer.set_camera([0.0, 0.0, 0.0])
    existing = tmp_path / "existing.html"
    existing.write_text("keep")
    with pytest.raises(InvalidInputError, match="exists"):
        viewer.export_html(existing)
    assert existing.read_text() == "keep"
    viewer.export_html(existing, force=True)
    assert existing.read_text() != "keep"


def test_close_stops_the_server():
    viewer = Viewer()
    process = viewer.server.process
    with viewer:
        assert process.poll() is None
    assert process.poll() is not None
    viewer.close()  # idempotent


def test_wait_reports_a_server_that_died():
    with Viewer() as viewer:
        viewer.server.process.kill()
        with pytest.raises(PhantomPinError, match="meshcat server stopped"):
            viewer.wait()


def _transforms(html: str) -> list[np.ndarray]:
    """Every set_transform matrix of an exported page's scene commands."""
    commands = json.loads(re.search(r"for \(const command of (\[.*?\])\)", html, re.S).group(1))
    messages = [umsgpack.unpackb(base64.b64decode(c)) for c in commands]
    return [np.array(m["matrix"], dtype=float) for m in messages if m["type"] == "set_transform"]


def test_tiny_force_draws_a_finite_arrow(viewer, tmp_path):
    """1e-300 N: |f| underflows to 0 if taken directly, which drew a NaN arrow."""
    viewer.set_force([1e-300, 0.0, 0.0])
    viewer.show(RAISED)
    html = viewer.export_html(tmp_path / "tiny.html").read_text()
    viewer.set_force(np.zeros(3))
    transforms = _transforms(html)
    assert transforms and all(np.isfinite(t).all() for t in transforms)
