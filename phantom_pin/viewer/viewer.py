"""Viewer: the arm in meshcat (postures, animations of the arm and a stylus gimbal, tip frame,
tip force, HTML export)."""

from __future__ import annotations

import base64
import contextlib
import io
import json
import re
import signal
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import meshcat
import meshcat.geometry as mg
import numpy as np
import pinocchio as pin
import umsgpack
from meshcat.animation import Animation

from phantom_pin._validation import as_state, as_states, output_path
from phantom_pin.dynamics.loader import load
from phantom_pin.exceptions import InvalidInputError, PhantomPinError
from phantom_pin.viewer.server import MeshcatServer


def _meshcat_visualizer() -> type:
    """pinocchio.visualize.MeshcatVisualizer. The package's __init__ also loads its viser viewer,
    which imports trimesh (0.47 s of CPU, scipy.spatial's among it) before it finds viser
    missing; where viser is not installed that viewer cannot work, so trimesh is held back for
    that import (unless something imported it already) and released after it (DEVELOPERS.md)."""
    import importlib.util
    import sys

    held = "trimesh" not in sys.modules and importlib.util.find_spec("viser") is None
    if held:
        sys.modules["trimesh"] = None  # type: ignore[assignment]   # import trimesh: ImportError
    try:
        from pinocchio.visualize import MeshcatVisualizer
    finally:
        if held and sys.modules.get("trimesh", False) is None:
            del sys.modules["trimesh"]
    return MeshcatVisualizer


MeshcatVisualizer = _meshcat_visualizer()

#: Camera position (m, base_link) from which the whole workspace is in view. meshcat
#: 0.3's orbit controls always look at the world origin, here the shoulder.
CAMERA_POSITION = np.array([0.42, 0.36, 0.22])
#: Default arrow length per newton of tip force (m/N).
FORCE_SCALE = 0.03
#: The force arrow's radius (m).
_ARROW_RADIUS = 0.0025
#: meshcat paths: the robot's root node, and the force arrow under it.
_ROOT = "phantom"
_FORCE_PATH = f"{_ROOT}/force"
#: Key frames per second of animate(): theta(t) is resampled at this rate.
_FPS = 30

#: One scene command of meshcat's static HTML: an asynchronous fetch of a data URI.
_COMMAND = re.compile(r'fetch\("data:application/octet-binary;base64,([A-Za-z0-9+/=]*)"\)'
                      r'\s*\.then\(res => res\.arrayBuffer\(\)\)\s*\.then\(buffer => '
                      r'viewer\.handle_command_bytearray\(new Uint8Array\(buffer\)\)\);')


def _in_order(html: str) -> str:
    """meshcat's static HTML with its scene commands run one after the other, in order,
    animations last.

    meshcat 0.3 replays each command through its own asynchronous fetch, so a large
    animation may be bound to a node before (and then lose it to) the node's set_object.
    """
    payloads = _COMMAND.findall(html)
    if not payloads:
        raise PhantomPinError("meshcat's static HTML has no scene commands in the expected form")
    is_animation = [umsgpack.unpackb(base64.b64decode(p))["type"] == "set_animation" for p in payloads]
    ordered = [p for p, a in zip(payloads, is_animation) if not a] + \
              [p for p, a in zip(payloads, is_animation) if a]
    script = (f"for (const command of {json.dumps(ordered)}) {{\n"
              "  viewer.handle_command_bytearray(Uint8Array.from(atob(command), c => c.charCodeAt(0)));\n}")
    first = _COMMAND.search(html)
    assert first is not None  # payloads were found by the same pattern
    start = first.start()
    return html[:start] + script + _COMMAND.sub("", html[start:])


def _arrow_rotation(direction: np.ndarray) -> np.ndarray:
    """A rotation taking meshcat's cylinder axis (local y) onto the unit ``direction``."""
    return pin.Quaternion.FromTwoVectors(np.array([0.0, 1.0, 0.0]), direction).matrix()


class Viewer:
    """The PHANToM 1.5 in a meshcat viewer served on 127.0.0.1.

    ``Viewer()`` starts a meshcat server in a child process (stopped by ``close()``,
    by leaving a ``with`` block, or at interpreter exit), loads ``phantom_pin.load()``
    (or the RobotWrapper you pass), frames the arm with the camera and shows the
    robot's q0. Joint vectors are the report's theta1..theta3 (rad); a model with a stylus
    gimbal (the Touch) draws the stylus at the ``gimbal`` angles given to show() and animate()
    (OpenHaptics' raw gimbal angles g1..g3, rad, the URDF's joint4..joint6; default zero). The
    scene's world frame is ``base_link`` (x forward, z up). ``url`` is the page to open.
    """

    def __init__(self, robot: pin.RobotWrapper | None = None) -> None:
        self.robot = load() if robot is None else robot
        self._guarded = False  # within stop_on_signals
        self.server = MeshcatServer()
        try:
            with contextlib.redirect_stdout(io.StringIO()):  # meshcat prints its URL
                scene = meshcat.Visualizer(zmq_url=self.server.zmq_url)
            self.visualizer = MeshcatVisualizer(self.robot.model, self.robot.collision_model,
                                                self.robot.visual_model)
            self.visualizer.initViewer(viewer=scene)
            self.visualizer.loadViewerModel(rootNodeName=_ROOT)
            self._tip = self.robot.model.getFrameId("tip")
            self._s = self.robot.model.getFrameId("report_s")
            self.visualizer.displayFrames(True, frame_ids=[self._tip], axis_length=0.04,
                                          axis_width=4)
            self._force = np.zeros(3)
            self.set_camera(CAMERA_POSITION)
            self.show(self.robot.q0[:3], self.robot.q0[3:] if self.robot.model.nq > 3 else None)
        except BaseException:
            self.server.stop()
            raise

    @property
    def url(self) -> str:
        """The viewer's web page, http://127.0.0.1:PORT/static/."""
        return self.server.web_url

    @property
    def scene(self) -> meshcat.Visualizer:
        """The meshcat scene, for drawing objects of your own."""
        return self.visualizer.viewer

    def set_camera(self, position: object) -> None:
        """Put the camera at ``position`` (3,) (m, base_link), looking at the shoulder.

        meshcat 0.3's orbit controls look at the world origin (base_link's origin,
        the shoulder); the user can orbit and zoom from there in the browser.
        """
        p = as_state(position, "position")
        if np.linalg.norm(p) < 1e-3:
            raise InvalidInputError("must be at least 1 mm away from the shoulder", argument="position")
        # meshcat's camera node is rotated so that three.js's y-up camera sees a z-up
        # world: its position is given as (x, z, -y).
        self.scene["/Cameras/default/rotated/<object>"].set_property("position", [p[0], p[2], -p[1]])

    def _configuration(self, theta: object, gimbal: object = None) -> np.ndarray:
        """The robot's q of ``theta`` (3,) and, for a model with a stylus gimbal, ``gimbal`` (3,)
        (rad; None: zero); InvalidInputError naming ``gimbal`` for a model without one."""
        q = as_state(theta, "theta")
        if self.robot.model.nq == 3:
            if gimbal is not None:
                raise InvalidInputError("this model has no stylus gimbal", argument="gimbal")
            return q
        return np.concatenate([q, np.zeros(3) if gimbal is None else as_state(gimbal, "gimbal")])

    def _motion(self, times: object, theta: object, gimbal: object) -> tuple[np.ndarray, np.ndarray]:
        """(times (N,) s, the robot's q (N, nq)) of animate()'s arguments, checked: theta
        (N, 3) rad; ``gimbal`` (N, 3) or (3,) rad held throughout, None for zero, a model with a
        stylus gimbal only (InvalidInputError naming ``gimbal`` otherwise)."""
        t = np.asarray(times, dtype=float)
        q, _ = as_states(theta, "theta")
        if t.ndim != 1 or q.shape != (t.size, 3) or t.size < 2:
            raise InvalidInputError(f"times, theta: expected shapes (N,) and (N, 3) with N >= 2, "
                                    f"got {t.shape} and {q.shape}")
        if not np.isfinite(t).all() or np.any(np.diff(t) <= 0):
            raise InvalidInputError("expected finite, strictly increasing seconds", argument="times")
        if self.robot.model.nq == 3:
            if gimbal is not None:
                raise InvalidInputError("this model has no stylus gimbal", argument="gimbal")
            return t, q
        g, batch = (np.zeros(3), False) if gimbal is None else as_states(gimbal, "gimbal")
        if batch and g.shape != (t.size, 3):
            raise InvalidInputError(f"expected shape (3,) or (N, 3) with N = {t.size} times, got {g.shape}",
                                    argument="gimbal")
        return t, np.hstack([q, np.broadcast_to(g, (t.size, 3))])

    def show(self, theta: object, gimbal: object = None) -> None:
        """Place the arm, its tip frame and the force arrow at ``theta`` (3,) (rad), and the
        stylus (a model with a gimbal) at ``gimbal`` (3,) (rad; default zero)."""
        self.visualizer.display(self._configuration(theta, gimbal))
        self._draw_force()

    def set_force(self, force: object, scale: float = FORCE_SCALE) -> None:
        """Draw the force on the tip (3,) (N, in the report's frame s) as an arrow of
        ``scale`` metres per newton starting at the tip; a zero force hides the arrow.
        The arrow follows the tip in later show() and animate() calls."""
        f = as_state(force, "force")
        if not (np.isfinite(scale) and scale > 0):
            raise InvalidInputError(f"expected a positive number of m/N, got {scale!r}", argument="scale")
        magnitude = float(np.abs(f).max())  # scaled first: |f| of a tiny f underflows to 0
        direction = f / magnitude if magnitude else f
        length = magnitude * float(np.linalg.norm(direction)) * scale
        if not np.isfinite(length):
            raise InvalidInputError("force, scale: the arrow would be infinitely long")
        self._force = direction  # only the direction is needed from here on
        node = self.scene[_FORCE_PATH]
        node.delete()
        if length == 0.0:
            return
        head = min(0.3 * length, 4 * _ARROW_RADIUS)
        material = mg.MeshLambertMaterial(color=0xD02020)
        node["shaft"].set_object(mg.Cylinder(length - head, _ARROW_RADIUS), material)
        node["shaft"].set_transform(pin.SE3(np.eye(3), np.array([0, (length - head) / 2, 0])).homogeneous)
        node["head"].set_object(mg.Cylinder(head, radiusTop=0.0, radiusBottom=2 * _ARROW_RADIUS), material)
        node["head"].set_transform(pin.SE3(np.eye(3), np.array([0, length - head / 2, 0])).homogeneous)
        self._draw_force()

    def _force_pose(self) -> np.ndarray:
        """World pose of the arrow: at the tip, local y along the force. Reads the frame
        placements of the visualizer's data, which display() (frames shown) and animate()
        update."""
        placements = self.visualizer.data.oMf
        direction = placements[self._s].rotation @ self._force
        return pin.SE3(_arrow_rotation(direction / np.linalg.norm(direction)),
                       placements[self._tip].translation).homogeneous

    def _draw_force(self) -> None:
        if self._force.any():
            self.scene[_FORCE_PATH].set_transform(self._force_pose())

    def animate(self, times: object, theta: object, repetitions: int = 1, gimbal: object = None) -> None:
        """Play theta(t) in the browser: ``times`` (N,) strictly increasing (s) and
        ``theta`` (N, 3) (rad), interpolated linearly in time and resampled at 30 key
        frames per second. The clip lives in the scene, so export_html() keeps it; it
        plays ``repetitions`` times on page load, then the scene shows the last posture.
        ``gimbal`` (a model with a stylus gimbal): OpenHaptics' raw gimbal angles (rad),
        (N, 3) one row per time (interpolated as theta) or (3,) held throughout; default
        zero. InvalidInputError naming ``gimbal`` for a model without one or a wrong shape."""
        t, q = self._motion(times, theta, gimbal)
        if not (isinstance(repetitions, int) and repetitions >= 1):
            raise InvalidInputError(f"expected a positive integer, got {repetitions!r}", argument="repetitions")
        # Resample q(t) at the frame rate so that every key frame is a true posture
        # (the browser interpolates each link's pose between key frames).
        samples = np.append(np.arange(0.0, t[-1] - t[0], 1.0 / _FPS), t[-1] - t[0])
        postures = np.stack([np.interp(samples, t - t[0], q[:, j]) for j in range(q.shape[1])], axis=1)
        animation = Animation(default_framerate=_FPS)
        model, data, geometry = self.robot.model, self.visualizer.data, self.robot.visual_model
        geometry_data = self.visualizer.visual_data
        frame_node = f"{self.visualizer.viewerFramesGroupName}/{model.frames[self._tip].name}"
        for instant, posture in zip(samples, postures):
            with animation.at_frame(self.scene, instant * _FPS) as frame:
                pin.forwardKinematics(model, data, posture)
                pin.updateGeometryPlacements(model, data, geometry, geometry_data)
                for k, obj in enumerate(geometry.geometryObjects):
                    name = self.visualizer.getViewerNodeName(obj, pin.GeometryType.VISUAL)
                    frame[name].set_transform(geometry_data.oMg[k].homogeneous)
                pin.updateFramePlacements(model, data)
                frame[frame_node].set_transform(data.oMf[self._tip].homogeneous)
                if self._force.any():
                    frame[_FORCE_PATH].set_transform(self._force_pose())
        self.scene.set_animation(animation, play=True, repetitions=repetitions)
        # the scene's own state: the last posture, shown when the clip ends
        self.show(q[-1, :3], q[-1, 3:] if q.shape[1] > 3 else None)

    def export_html(self, path: Path | str, force: bool = False) -> Path:
        """Write the scene (with its camera and animation) as one self-contained HTML
        file that opens in any browser without a server; an existing file is kept
        unless ``force``. Returns the path."""
        output = output_path(path, force, "path")
        output.write_text(_in_order(self.scene.static_html()), encoding="utf-8")
        return output

    @contextlib.contextmanager
    def stop_on_signals(self) -> Iterator[None]:
        """A block that the first SIGINT (Ctrl-C) or SIGTERM ends quietly, wherever it is in
        the block; a later signal within it is ignored, so that clean-up in the block (for
        example ``close()`` in a ``finally``) runs to its end.

        In the main thread it installs its own handlers, even where the parent started the
        process with SIGINT ignored (as background jobs and some CI shells do, and as Python
        then leaves it), and restores the previous ones when the block ends. Elsewhere it
        installs nothing (Python delivers signals to the main thread only). Nested in
        another such block, it leaves the signals to the outer one."""
        if self._guarded:
            yield
            return
        fired = False

        def interrupt(*_: object) -> None:
            nonlocal fired
            if not fired:
                fired = True
                raise KeyboardInterrupt

        handlers = {}
        if threading.current_thread() is threading.main_thread():
            handlers = {sig: signal.signal(sig, interrupt) for sig in (signal.SIGINT, signal.SIGTERM)}
        self._guarded = True
        try:
            yield
        except KeyboardInterrupt:
            pass
        finally:
            self._guarded = False
            for sig, handler in handlers.items():
                signal.signal(sig, handler)

    def wait(self) -> None:
        """Block until Ctrl-C (SIGINT) or SIGTERM, keeping the live viewer served (within
        ``stop_on_signals``); raise PhantomPinError if the server process ends first."""
        with self.stop_on_signals():
            while self.server.running:
                time.sleep(0.5)
            raise PhantomPinError(f"the meshcat server stopped (exit code {self.server.process.returncode})")

    def close(self) -> None:
        """Stop the meshcat server; idempotent."""
        self.server.stop()

    def __enter__(self) -> Viewer:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
