"""The exported HTML rendered by headless chromium (helpers.render), checked against a
pinhole projection of Pinocchio's kinematics (helpers.project); the stylus's animation as the
page carries it, against Pinocchio's placement of the stylus link on the Touch URDF."""

import base64
import json
import re
import xml.etree.ElementTree as ET

import numpy as np
import pinocchio as pin
import pytest
import umsgpack

from helpers import RAISED, RESTING, dark, frame_pose, patch, red, render
from phantom_pin import config, describe, load
from phantom_pin.config import MODELS
from phantom_pin.config.sampling import sample_postures
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


# -- the stylus in an animation (a model with a gimbal) -------------------------------------------

TOUCH_URDF = MODELS["touch"].urdf
#: Key frames per second of Viewer.animate; times on its grid make each key frame a given state.
FPS = 30


@pytest.fixture(scope="module")
def touch_viewer():
    with Viewer(load(describe("touch"))) as v:
        yield v


def touch_states(n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """``n`` seeded (theta, gimbal) (rad): theta inside the Touch's limits and stops, the gimbal
    inside its ranges (the configuration's)."""
    touch = config.read("touch")
    rng = np.random.default_rng(seed)
    return sample_postures(touch.limits, n, rng), rng.uniform(touch.gimbal.lower, touch.gimbal.upper, (n, 3))


def stylus_link_poses(theta: np.ndarray, gimbal: np.ndarray) -> np.ndarray:
    """(N, 4, 4): where the stylus link's visual (its cylinder) is, by Pinocchio on the committed
    Touch URDF (its own mimic joints; angles set by joint name): the link frame's placement
    times the visual's <origin> read from the URDF."""
    text = TOUCH_URDF.read_text()
    model = pin.buildModelFromXML(text, mimic=True)
    data = model.createData()
    origin = ET.fromstring(text).find("link[@name='stylus_link']/visual/origin")
    visual = pin.SE3(pin.rpy.rpyToMatrix(*map(float, origin.get("rpy").split())),
                     np.array([float(v) for v in origin.get("xyz").split()]))
    index = [model.joints[model.getJointId(f"joint{j}")].idx_q for j in range(1, 7)]
    frame = model.getFrameId("stylus_link", pin.BODY)
    poses = []
    for angles in np.hstack([theta, gimbal]):
        q = pin.neutral(model)
        q[index] = angles
        pin.framesForwardKinematics(model, data, q)
        poses.append((data.oMf[frame] * visual).homogeneous)
    return np.array(poses)


def _messages(html: str) -> list[dict]:
    commands = json.loads(re.search(r"for \(const command of (\[.*?\])\)", html, re.S).group(1))
    return [umsgpack.unpackb(base64.b64decode(c)) for c in commands]


def animated(html: str, node: str) -> tuple[np.ndarray, np.ndarray]:
    """(key times in frames (K,), poses (K, 4, 4)) of the animation track of the scene node whose
    path ends with ``node``, as the exported page carries them (position and x, y, z, w
    quaternion per key)."""
    clips = [a["clip"] for m in _messages(html) if m["type"] == "set_animation" for a in m["animations"]
             if a["path"].endswith("/" + node)]
    assert len(clips) == 1, f"{node}: {len(clips)} animation clips"
    tracks = {track["name"]: track["keys"] for track in clips[0]["tracks"]}
    times = np.array([key["time"] for key in tracks[".position"]])
    assert np.array_equal(times, [key["time"] for key in tracks[".quaternion"]])
    poses = np.tile(np.eye(4), (len(times), 1, 1))
    for pose, position, quaternion in zip(poses, tracks[".position"], tracks[".quaternion"]):
        x, y, z, w = quaternion["value"]
        pose[:3, :3] = pin.Quaternion(w, x, y, z).matrix()
        pose[:3, 3] = position["value"]
    return times, poses


def static(html: str, node: str) -> np.ndarray:
    """The last set_transform of the scene node whose path ends with ``node`` (its shown pose)."""
    matrices = [m["matrix"] for m in _messages(html) if m["type"] == "set_transform" and m["path"].endswith("/" + node)]
    return np.array(matrices[-1], dtype=float).reshape(4, 4).T  # three.js: column-major


def test_an_animation_moves_the_stylus_where_pinocchio_puts_it(touch_viewer, tmp_path):
    """animate(times, theta, gimbal=(N, 3)) on the Touch: every key frame of the stylus link's
    node in the exported page is Pinocchio's placement of that link (the committed URDF) at
    that key's six angles, to 1e-12 (m, rotation entries), over 12 seeded states inside the
    stops and the gimbal's ranges at 30 frames per second; the scene's own state is the last.
    A (3,) gimbal is held throughout, and no gimbal is the neutral stylus (zero)."""
    theta, gimbal = touch_states(12, seed=42)
    times = np.arange(12) / FPS
    touch_viewer.animate(times, theta, gimbal=gimbal)
    html = touch_viewer.export_html(tmp_path / "stylus.html").read_text()
    keys, poses = animated(html, "stylus_link_0")
    expected = stylus_link_poses(theta, gimbal)
    assert np.array_equal(keys, np.arange(12))
    assert np.abs(poses - expected).max() < 1e-12
    assert np.abs(static(html, "stylus_link_0") - expected[-1]).max() < 1e-12
    assert np.abs(expected[:, :3, :3] - expected[0, :3, :3]).max() > 0.5  # the stylus did turn
    for held, name in ((gimbal[3], "held"), (None, "zero")):
        touch_viewer.animate(times, theta, gimbal=held)
        html = touch_viewer.export_html(tmp_path / f"{name}.html").read_text()
        reference = stylus_link_poses(theta, np.tile(np.zeros(3) if held is None else held, (12, 1)))
        assert np.abs(animated(html, "stylus_link_0")[1] - reference).max() < 1e-12, name


def test_an_animations_gimbal_is_refused_where_it_cannot_be_drawn(viewer, touch_viewer):
    """A gimbal for a model without one, a gimbal of another length than the times, or not
    finite: InvalidInputError naming ``gimbal``."""
    times, theta = [0.0, 1.0], [RESTING, RAISED]
    for target, gimbal in ((viewer, np.zeros(3)), (touch_viewer, np.zeros((3, 3))),
                           (touch_viewer, [[0.0, np.nan, 0.0], [0.0, 0.0, 0.0]]), (touch_viewer, [0.0, 0.0])):
        with pytest.raises(InvalidInputError) as error:
            target.animate(times, theta, gimbal=gimbal)
        assert error.value.argument == "gimbal", gimbal


def test_show_trajectory_plays_the_files_stylus_angles(tmp_path, cli):
    """`--model touch show --trajectory FILE --html`: a CSV with t, theta1..3 and gimbal1..3 (with
    units, as simulate writes its columns) is played, each key frame of the stylus link at
    Pinocchio's placement of its row (1e-12); a file without gimbal columns holds --gimbal."""
    theta, gimbal = touch_states(6, seed=43)
    times = np.arange(6) / FPS
    path = tmp_path / "motion.csv"
    header = ",".join(["t [s]", *(f"{name}{j} [rad]" for name in ("theta", "gimbal") for j in (1, 2, 3))])
    np.savetxt(path, np.column_stack([times, theta, gimbal]), delimiter=",", header=header, comments="", fmt="%.17g")
    code, out, err = cli("--model", "touch", "show", "--trajectory", path, "--html", tmp_path / "motion.html")
    assert (code, err) == (0, "") and out == f"wrote {tmp_path / 'motion.html'}\n"
    keys, poses = animated((tmp_path / "motion.html").read_text(), "stylus_link_0")
    assert np.array_equal(keys, np.arange(6))
    assert np.abs(poses - stylus_link_poses(theta, gimbal)).max() < 1e-12
    arm_only = tmp_path / "arm.csv"
    np.savetxt(arm_only, np.column_stack([times, theta]), delimiter=",", header="t,theta1,theta2,theta3", comments="")
    code, out, err = cli("--model", "touch", "show", "--trajectory", arm_only, "--gimbal", *gimbal[0],
                         "--html", tmp_path / "held.html")
    assert (code, err) == (0, ""), err
    poses = animated((tmp_path / "held.html").read_text(), "stylus_link_0")[1]
    assert np.abs(poses - stylus_link_poses(theta, np.tile(gimbal[0], (6, 1)))).max() < 1e-12


def test_show_trajectory_refuses_what_it_cannot_play(tmp_path, cli):
    """One line naming the option, exit 2, nothing written: gimbal columns for a model without a
    gimbal, some of the gimbal's columns but not all, gimbal columns and --gimbal, --theta with
    --trajectory, times not increasing, a missing file. Angles beyond the stops: one warning."""
    rows = np.array([[0.0, 0.0, 0.5, 0.7, 0.1, 0.2, 0.3], [1.0, 0.1, 0.6, 0.8, 0.2, 0.3, 3.0]])
    files = {}
    for name, header, table in (("six", "t,theta1,theta2,theta3,gimbal1,gimbal2,gimbal3", rows),
                                ("five", "t,theta1,theta2,theta3,gimbal1,gimbal2", rows[:, :6]),
                                ("back", "t,theta1,theta2,theta3", rows[::-1, :4])):
        files[name] = tmp_path / f"{name}.csv"
        np.savetxt(files[name], table, delimiter=",", header=header, comments="")
    html = tmp_path / "out.html"
    for argv, option in (((files["six"],), "--trajectory"), (("--model", "touch", files["five"]), "--trajectory"),
                         (("--model", "touch", files["six"], "--gimbal", 0, 0, 0), "--gimbal"),
                         (("--model", "touch", files["six"], "--theta", 0, 0.5, 0.7), "--theta"),
                         ((files["back"],), "--trajectory"), ((tmp_path / "none.csv",), "--trajectory")):
        model, rest = (argv[:2], argv[2:]) if argv[0] == "--model" else ((), argv)
        code, out, err = cli(*model, "show", "--trajectory", *rest, "--html", html)
        assert (code, out) == (2, "") and err.count("\n") == 1, err
        assert err.startswith(f"phantom-pin: error: {option}: "), err
        assert not html.exists()
    code, out, err = cli("--model", "touch", "show", "--trajectory", files["six"], "--html", html)
    assert code == 0 and err.count("\n") == 1 and "warning: --trajectory: gimbal" in err and "t = 1 s" in err, err


def test_the_viewer_holds_back_trimesh_and_leaves_it_importable():
    """pinocchio.visualize's viser viewer imports trimesh (0.47 s) even where viser is missing;
    the viewer holds it back for that import alone. In a fresh interpreter: after importing the
    viewer, trimesh is not loaded (where viser is missing; loaded where viser is installed), and
    then imports and works (yourdfpy needs it)."""
    import subprocess
    import sys

    script = ("import importlib.util, sys\n"
              "held = importlib.util.find_spec('viser') is None   # with viser, pinocchio's viewer works\n"
              "import phantom_pin.viewer\n"
              "assert ('trimesh' in sys.modules) != held, 'trimesh held back with viser, or not without'\n"
              "import trimesh\n"
              "assert trimesh.creation.box().volume == 1.0\n")
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
