"""What the tests share besides fixtures: the default model's configuration and files, frame
poses by Pinocchio, relative errors, the Touch's six-joint model (Six), logs and trajectories
with a known truth, and the browser helpers: render an HTML file in headless chromium, project
a world point to its pixel with meshcat's camera (75 degrees vertical field of view, looking at
the world origin, z up, from viewer.CAMERA_POSITION)."""

import ctypes
import dataclasses
import functools
import json
import os
import re
import shutil
import subprocess
import sys
from contextlib import redirect_stderr, redirect_stdout
from io import StringIO
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pinocchio as pin
import pytest
import yaml
from PIL import Image

from phantom_pin import Device, Phantom, closed_form, config, describe
from phantom_pin.config.sampling import sample_postures
from phantom_pin.identification.data import io, simulation
from phantom_pin.identification.structure import parameterization as pz
from phantom_pin.identification.structure.structures import General
from phantom_pin.interfaces import profiles
from phantom_pin.viewer import CAMERA_POSITION
from phantom_pin.viewer.screenshot import chromium_command

N_STATES = 1000
#: The default model's configuration (premium_1_5) and the report's numbers it holds.
CONFIG = config.read()
REPORT = CONFIG.report
#: Its configuration folder and committed generated files.
MODEL = config.MODELS["premium_1_5"]
CONFIG_DIR, URDF_PATH, SRDF_PATH, MJCF_PATH, SCENE_PATH = MODEL.config, MODEL.urdf, MODEL.srdf, MODEL.mjcf, MODEL.scene


def run_cli(*arguments: object) -> tuple[int, str, str]:
    """phantom-pin in this process: the command line's main() on ``arguments`` (each passed as
    str), and its (exit code, stdout, stderr). The one runner of the tests (conftest's ``cli``
    fixture is this; a module fixture calls it directly)."""
    from phantom_pin.cli import main

    out, err = StringIO(), StringIO()
    with redirect_stdout(out), redirect_stderr(err):
        code = main([str(a) for a in arguments])
    return code, out.getvalue(), err.getvalue()


def frame_pose(model: pin.Model, theta: np.ndarray, name: str) -> pin.SE3:
    """World pose of the frame ``name`` at theta (rad), by Pinocchio's forward kinematics."""
    data = model.createData()
    pin.framesForwardKinematics(model, data, np.asarray(theta, dtype=float))
    return pin.SE3(data.oMf[model.getFrameId(name)])  # a copy, independent of data


def relative_error(actual: np.ndarray, expected: np.ndarray) -> float:
    """max |actual - expected| / max |expected| over the whole array."""
    return float(np.abs(actual - expected).max() / np.abs(expected).max())


# -- the stylus gimbal held at given angles (tests/dynamics, tests/device, tests/cli) -----------
#: far from locked_at (0): the stylus's load differs by percents of the arm's torques
HELD = np.array([1.0, -0.8, 1.2])


class Six:
    """The Touch's six-joint model built here from its committed URDF with Pinocchio alone (the
    gimbal free, the configuration's g along base_link's -z): the arm's rows and columns of its
    dynamics with the gimbal at rest are what the arm's methods with gimbal= compute (the
    fixture ``six`` of conftest.py)."""

    def __init__(self):
        self.model = pin.buildModelFromXML(config.MODELS["touch"].urdf.read_text(), mimic=True)
        self.model.gravity = pin.Motion(np.array([0.0, 0.0, -config.read("touch").gravity]), np.zeros(3))
        self.data = self.model.createData()
        names = [f"joint{j}" for j in range(1, 7)]
        self.order = [self.model.joints[self.model.getJointId(n)].idx_q for n in names]
        self.arm = self.order[:3]

    def q(self, theta, gimbal=None):
        """The six joints' vector of the arm's theta (rad), with the gimbal's angles or zero."""
        q = np.zeros(6)
        q[self.order] = np.concatenate([theta, np.zeros(3) if gimbal is None else gimbal])
        return q

    def mass(self, theta, gimbal):
        return pin.crba(self.model, self.data, self.q(theta, gimbal))[np.ix_(self.arm, self.arm)]

    def torques(self, theta, gimbal, dtheta, ddtheta):
        return pin.rnea(self.model, self.data, self.q(theta, gimbal), self.q(dtheta), self.q(ddtheta))[self.arm]

    def pose(self, theta, gimbal, frame):
        """A frame's pose in frame s (report_s), (4, 4)."""
        pin.framesForwardKinematics(self.model, self.data, self.q(theta, gimbal))
        s = self.data.oMf[self.model.getFrameId("report_s")]
        return (s.inverse() * self.data.oMf[self.model.getFrameId(frame)]).homogeneous

    def energy(self, theta, gimbal, dtheta):
        """T + V (J): 1/2 dtheta^T M dtheta, and the sum of -m g . c over the bodies (each centre
        of mass c placed by the forward kinematics)."""
        pin.forwardKinematics(self.model, self.data, self.q(theta, gimbal))
        potential = -sum(inertia.mass * self.model.gravity.linear @ placement.act(inertia.lever)
                         for inertia, placement in zip(self.model.inertias, self.data.oMi))
        return 0.5 * dtheta @ self.mass(theta, gimbal) @ dtheta + potential


# -- logs with a known truth (tests/identification, tests/cli) ----------------------------------
#: 10 s at 1 kHz (s)
T10 = np.arange(10001) / 1000.0


def sines(t, amplitude=0.2, seed=1):
    """Five sines per joint of seeded frequencies (0.1-1 Hz) and phases around (0, 0.3, 0.45) rad,
    at any times ``t`` (s): theta, dtheta, ddtheta, exact."""
    rng = np.random.default_rng(seed)
    w, phase = 2 * np.pi * rng.uniform(0.1, 1.0, (3, 5)), rng.uniform(0, 2 * np.pi, (3, 5))
    arg, a = w * t[:, None, None] + phase, amplitude / 5
    return (np.array([0.0, 0.3, 0.45]) + a * np.sin(arg).sum(-1), a * (w * np.cos(arg)).sum(-1),
            -a * (w**2 * np.sin(arg)).sum(-1))


def model_torques(phantom, theta, dtheta, ddtheta, coulomb=None):
    """The model's inverse dynamics plus the shipped friction law (its Coulomb torques replaced)."""
    law = phantom.config.actuation.friction
    coulomb = law.coulomb if coulomb is None else coulomb
    return (phantom.inverse_dynamics(theta, dtheta, ddtheta) + np.array(law.viscous) * dtheta
            + np.array(coulomb) * np.sign(dtheta))


def recorded_trajectory(path, record=None, model="touch"):
    """A 2.5 s trajectory at 1 kHz in the report's convention (sines about a posture inside the
    stops, exact derivatives, the model's torques), written here with ``record`` as its second
    line (None: none, as files before 0.5.0)."""
    t = np.arange(2501) / 1000
    w = 2 * np.pi * np.array([0.4, 0.6, 0.5])
    theta = np.array([0.0, 0.3, 0.5]) + 0.1 * np.sin(np.outer(t, w))
    dtheta, ddtheta = 0.1 * w * np.cos(np.outer(t, w)), -0.1 * w**2 * np.sin(np.outer(t, w))
    tau = Phantom.from_model(model).inverse_dynamics(theta, dtheta, ddtheta)
    lines = ["t,theta1,theta2,theta3,dtheta1,dtheta2,dtheta3,ddtheta1,ddtheta2,ddtheta3,tau1,tau2,tau3"]
    lines += [] if record is None else [record]
    lines += [",".join(map(repr, row)) for row in np.column_stack([t, theta, dtheta, ddtheta, tau]).tolist()]
    path.write_text("\n".join(lines) + "\n")
    return path


#: The Fourier series `phantom-pin [--model touch] excite --restarts 1` optimised once (its "command").
EXCITATIONS = Path(__file__).parent / "data" / "excitations.json"


def excitation_file(path, model="touch"):
    """The file `phantom-pin --model MODEL excite -o PATH --restarts 1` writes (its defaults: 20 s
    at 1 kHz), from the series EXCITATIONS recorded (model "touch" or "premium_1_5"): the same
    rows to the last bits of the evaluation's products, on any machine and for any future
    optimiser, so that a test of a method's property keeps its case (issue 50, 2)."""
    from phantom_pin.cli.common import csv_text
    from phantom_pin.identification.data.io import TRAJECTORY_COLUMNS
    from phantom_pin.identification.fitting.excitation import Fourier

    series = json.loads(EXCITATIONS.read_text())[model]
    trajectory = Fourier(*(np.array(series[key]) for key in ("q0", "a", "b")), series["period"])
    phantom = Phantom.from_model(model)
    t = np.arange(20001) / 1000
    theta, dtheta, ddtheta = trajectory(t)
    tau = phantom.inverse_dynamics(theta, dtheta, ddtheta) + phantom.config.actuation.friction.torque(dtheta)
    path.write_text(csv_text(list(TRAJECTORY_COLUMNS), np.column_stack([t, theta, dtheta, ddtheta, tau]),
                             phantom.config.name, "report"))
    return path


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
    drawn by phantom_pin.viewer.plots."""
    group = re.search(rf'<g id="{re.escape(gid)}">\s*<path d="([^"]*)"', page)
    assert group is not None, gid
    return np.array([float(v) for v in re.findall(r"-?\d+(?:\.\d+)?", group.group(1))]).reshape(-1, 2)


def affine(source: np.ndarray, image: np.ndarray) -> tuple[float, float, float]:
    """(a, b, worst residual / span) of the least-squares fit image = a source + b."""
    a, b = np.polyfit(source, image, 1)
    return a, b, float(np.abs(a * source + b - image).max() / np.ptp(image))


def check_page(html: Path, tmp_path: Path, figures: int) -> str:
    """A phantom_pin.viewer.plots page renders in chromium with something drawn, no console line and no
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


# -- shared by several test files (issue 51: no test file imports another's helpers) ---------

#: The arm's actuated joints.
ACTUATED = ("joint1", "joint2", "joint3")
#: Fast DDS's discovery announcements for processes on loopback (the file says why).
DISCOVERY = str(Path(__file__).with_name("fastdds_loopback.xml"))
#: The scripts of examples/.
EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def inside_stops(n: int, seed: int, pool: np.ndarray | None = None, config_dir: Path = CONFIG_DIR) -> np.ndarray:
    """At most ``n`` seeded theta (rad), uniform in the URDF box and inside the coupled
    stops of ``config_dir``'s joint_limits.yaml: the first of ``pool`` (default: 4 n seeded
    states in the box) that are inside."""
    limits = yaml.safe_load((config_dir / "joint_limits.yaml").read_text())
    stops = limits["stops"]
    if pool is None:
        lower = [limits[j]["lower"] for j in ACTUATED]
        upper = [limits[j]["upper"] for j in ACTUATED]
        pool = np.random.default_rng(seed).uniform(lower, upper, (4 * n, 3))
    keep = ((pool[:, 1] - pool[:, 2] <= stops["theta2_minus_theta3_max"])
            & (pool[:, 2] - pool[:, 1] <= stops["theta3_minus_theta2_max"]))
    return pool[keep][:n]


class MujocoArm:
    """A MuJoCo model with its joints addressed in the coupling's tree order."""

    def __init__(self, model, coupling: object, case: object = None) -> None:
        import mujoco  # the MuJoCo tests only: imported by the first arm

        self.mujoco = mujoco
        self.model, self.data, self.coupling, self.case = model, mujoco.MjData(model), coupling, case
        names = [model.joint(i).name for i in range(model.njnt)]
        assert sorted(names) == sorted(coupling.tree.names[1:])
        self.qpos = [model.jnt_qposadr[names.index(n)] for n in coupling.tree.names[1:]]
        self.dof = [model.jnt_dofadr[names.index(n)] for n in coupling.tree.names[1:]]

    def set(self, theta: np.ndarray) -> None:
        full = theta if self.case is None else self.case.full(theta)  # a model without a gimbal: theta
        self.data.qpos[self.qpos] = self.coupling.configuration(full)
        self.data.qvel[:] = 0
        self.mujoco.mj_forward(self.model, self.data)

    def reduced_mass_and_gravity(self, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        self.set(theta)
        full = np.zeros((self.model.nv, self.model.nv))
        self.mujoco.mj_fullM(self.model, self.data, full)
        tree = full[np.ix_(self.dof, self.dof)]
        G = self.coupling.matrix  # the arm's block: the gimbal held (locked) at rest
        return (G.T @ tree @ G)[:3, :3], (G.T @ self.data.qfrc_bias[self.dof])[:3]  # bias at rest = gravity


def ros_environment(domain: int | None = None) -> dict[str, str]:
    """Loopback only, Fast DDS's discovery of DISCOVERY, and a ROS domain of this test run alone
    (``domain``, else one from the process id)."""
    return {**os.environ, "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST", "FASTDDS_DEFAULT_PROFILES_FILE": DISCOVERY,
            "ROS_DOMAIN_ID": str(1 + os.getpid() % 100 if domain is None else domain), "PYTHONUNBUFFERED": "1"}


def in_process(environment: dict[str, str]) -> None:
    """This process's own nodes (rclpy in the test) in ``environment``'s domain and discovery."""
    os.environ.update({k: v for k, v in environment.items() if k.startswith(("ROS_", "FASTDDS_"))})


def stop_process(process: subprocess.Popen, sig: int) -> tuple[int, str]:
    process.send_signal(sig)
    try:
        _, err = process.communicate(timeout=20)
    except subprocess.TimeoutExpired:
        process.kill()
        _, err = process.communicate()
        raise AssertionError(f"the node did not stop on signal {sig}: {err}") from None
    return process.returncode, err


def run_script(script: str, out: Path, *argv: str, env: dict[str, str] | None = None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, str(EXAMPLES / script), "--out", str(out), *argv],
                          capture_output=True, text=True, timeout=300, env=env)


def number(pattern: str, text: str) -> float:
    match = re.search(pattern, text)
    assert match, f"{pattern!r} not in the output:\n{text}"
    return float(match.group(1))


def figure(path: Path) -> None:
    with Image.open(path) as image:
        assert image.format == "PNG" and image.width >= 600 and image.height >= 400


def message(profile: object) -> SimpleNamespace:
    """An empty force message of the profile's type, as attributes (the ROS classes' layout)."""
    vector = SimpleNamespace(x=0.0, y=0.0, z=0.0)
    kind = profile.force.type.rsplit("/", 1)[1]
    if kind == "Vector3":
        return vector
    if kind == "WrenchStamped":
        return SimpleNamespace(header=SimpleNamespace(stamp=None), wrench=SimpleNamespace(force=vector))
    return SimpleNamespace(force=vector)


# The generated C header (tests/codegen/, tests/cli/test_codegen.py): generated once per
# arguments in a process (conftest.GROUPS keeps its tests on one worker), compiled and called.

#: An identified-style overlay on the CAD model: masses, centres of mass off the links' axes and
#: products of inertia, as `phantom-pin identify` writes them (links.NAME.{mass,com.k,inertia.xy}),
#: each a number the CAD already has nonzero (a zero made nonzero doubles SymPy's work: 7.5 s of CPU
#: against 3.5 s, for the same code paths).
OVERLAY = {"links.forearm_link.com.0": 3.1e-05, "links.forearm_link.mass": 0.028,
           "links.turret_link.inertia.xz": -1.9e-04, "links.lower_bar_link.com.0": 0.1012,
           "links.crank_link.inertia.xy": 3.5e-06, "links.upper_arm_link.com.1": 0.0022,
           "links.upper_arm_link.inertia.yz": 3e-6, "links.crank_link.mass": 0.2}


STRICT_C = ["gcc", "-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic"]
STRICT_CXX = ["g++", "-std=c++17", "-Wall", "-Wextra", "-Werror", "-pedantic"]


#: A shared library over the header: each function looped over n states (row-major arrays).
SHIM = """#include "model.h"
#define LOOP(name, call) void batch_##name(int n, const double *a, const double *b, \\
    const double *c, double *out) { int k; (void)b; (void)c; for (k = 0; k < n; ++k) { call; } }
LOOP(gravity, phantom_gravity(a + 3 * k, out + 3 * k))
LOOP(inverse_dynamics, phantom_inverse_dynamics(a + 3 * k, b + 3 * k, c + 3 * k, out + 3 * k))
LOOP(mass_matrix, phantom_mass_matrix(a + 3 * k, out + 9 * k))
LOOP(coriolis, phantom_coriolis(a + 3 * k, b + 3 * k, out + 3 * k))
LOOP(tip_position, phantom_tip_position(a + 3 * k, out + 3 * k))
LOOP(tip_jacobian, phantom_tip_jacobian(a + 3 * k, out + 9 * k))
LOOP(jacobian_transpose_force, phantom_jacobian_transpose_force(a + 3 * k, b + 3 * k, out + 3 * k))
LOOP(theta_from_openhaptics, phantom_theta_from_openhaptics(a + 3 * k, out + 3 * k))
LOOP(openhaptics_torque_from_tau, phantom_openhaptics_torque_from_tau(a + 3 * k, out + 3 * k))
"""


@functools.cache
def _generated(name, prefix, overlay):
    from phantom_pin.codegen import header

    return header(name, prefix=prefix, overrides=dict(overlay) if overlay else None)


def generated(name, prefix="phantom", overrides=None):
    """header(name, prefix, overrides), generated once per arguments in this process (SymPy
    takes seconds); the tests of header()'s own errors call it directly."""
    return _generated(name, prefix, tuple(sorted((overrides or {}).items())))


def build(text, folder, shim=SHIM):
    """Compile ``text`` as model.h: strictly as C99 and C++17 (objects), then the ``shim`` as a
    shared library (-O2); returns the ctypes library. Fails in one line without gcc and g++."""
    if not (shutil.which("gcc") and shutil.which("g++")):
        pytest.fail("gcc and g++ compile the header: apt-get install g++ (.ci/run installs it)", pytrace=False)
    (folder / "model.h").write_text(text)
    (folder / "shim.c").write_text(shim)
    (folder / "shim.cpp").write_text(shim)
    subprocess.run([*STRICT_C, "-O2", "-fPIC", "-shared", "shim.c", "-o", "libmodel.so", "-lm"],
                   cwd=folder, check=True, capture_output=True, text=True)
    subprocess.run([*STRICT_CXX, "-O2", "-c", "shim.cpp", "-o", "shim_cpp.o"], cwd=folder, check=True,
                   capture_output=True, text=True)
    return ctypes.CDLL(str(folder / "libmodel.so"))


def call(library, name, width, a, b=None, c=None):
    """The batch_<name> of the library on (n, 3) arrays: (n, width)."""
    a = np.ascontiguousarray(a, dtype=float)
    out = np.empty((len(a), width))
    pointer = ctypes.POINTER(ctypes.c_double)
    args = [np.ascontiguousarray(x if x is not None else a, dtype=float) for x in (b, c)]
    getattr(library, f"batch_{name}")(ctypes.c_int(len(a)), a.ctypes.data_as(pointer),
                                      args[0].ctypes.data_as(pointer), args[1].ctypes.data_as(pointer),
                                      out.ctypes.data_as(pointer))
    return out


#: The drivers' profiles, by name (robots/phantom_description/config/drivers/).
PROFILES = profiles.names()


def installed_profiles() -> list[str]:
    """The drivers' profiles whose force message type installs here (the others' node refuses)."""
    from phantom_pin.exceptions import MissingDataError
    from phantom_pin.interfaces.ros2.node import message_type

    def _installed(name: str) -> bool:
        try:
            message_type(profiles.load(name).force.type)
        except MissingDataError:
            return False
        return True

    return [name for name in profiles.names() if _installed(name)]
# The identification's logs with a known truth (tests/identification: each module's helpers that
# another module takes).


def seeded_states(regressor, n, seed):
    """Seeded states inside the limits of the regressor's configuration."""
    rng = np.random.default_rng(seed)
    theta = sample_postures(regressor.phantom.config.limits, n, np.random.default_rng(seed), draws=4 * n)
    return theta, rng.normal(0, 2, (n, 3)), rng.normal(0, 20, (n, 3))


TRAJECTORY_RATE = 1000.0
TRAJECTORY_W = 2 * np.pi / 5          # rad/s: the trajectory's base frequency (period 5 s)
#: rad; rows: joints, columns: harmonics 1..3
TRAJECTORY_AMPLITUDE = np.array([[0.5, 0.0, 0.0], [0.0, 0.3, 0.0], [0.2, 0.0, 0.4]])
TRAJECTORY_PHASE = np.array([0.4, 0.3, 1.0])
TRAJECTORY_OFFSET = np.array([0.0, 0.3, 0.45])  # rad: inside every stop (theta3 - theta2 <= 0.95 < 55 deg)


def three_frequency_log(joint1_scale: float = 1.0, noise=(0.0, 0.0, 0.0), start: float = 0.0,
                        end: float = 10.0) -> io.Log:
    """The log of the three-frequency trajectory (exact rates and accelerations; the report's
    inverse dynamics plus the friction law: the true beta is constants.nominal's) from ``start``
    to ``end`` (s), joint 1's amplitude scaled, with white torque noise of standard deviation
    ``noise`` (N m) per joint (seeded)."""
    t = np.arange(round(start * TRAJECTORY_RATE), round(end * TRAJECTORY_RATE) + 1) / TRAJECTORY_RATE
    k = np.arange(1, 4)
    phase = np.multiply.outer(t, k * TRAJECTORY_W) + TRAJECTORY_PHASE[:, None, None].T[0]    # (N, 3 harmonics)
    amplitude = TRAJECTORY_AMPLITUDE * np.array([joint1_scale, 1.0, 1.0])[:, None]
    theta = TRAJECTORY_OFFSET + np.sin(phase) @ amplitude.T
    dtheta = (np.cos(phase) * k * TRAJECTORY_W) @ amplitude.T
    ddtheta = (-np.sin(phase) * (k * TRAJECTORY_W) ** 2) @ amplitude.T
    tau = closed_form.inverse_dynamics(theta, dtheta, ddtheta, REPORT) + CONFIG.actuation.friction.torque(dtheta)
    tau = tau + np.random.default_rng(0).standard_normal(tau.shape) * np.asarray(noise)
    return io.Log(t - t[0], theta, tau)


#: The simulated device: every report parameter moved by 10-30 % (physically consistent).
FACTORS = {"ma": 1.2, "Iaxx": 1.2, "Iayy": 1.2, "Iazz": 1.2, "mc": 0.85, "Icxx": 0.85, "Icyy": 0.85,
           "Iczz": 0.85, "mbe": 1.25, "l5": 1.1, "Ibexx": 1.15, "Ibeyy": 1.2, "Ibezz": 1.3,
           "mdf": 1.3, "l6": 0.9, "Idfxx": 1.2, "Idfyy": 1.1, "Idfzz": 1.25, "Ibaseyy": 1.15}
VISCOUS, COULOMB, TORQUE_NOISE = 8e-4, 0.015, 0.005       # N m s/rad, N m, N m (1 sigma)


def truth():
    p = REPORT
    return dataclasses.replace(p, **{k: getattr(p, k) * f for k, f in FACTORS.items()})


def true_x():
    """The simulated device's report parameters (parameterization.NAMES)."""
    t = truth()
    return np.array([t.ma, t.Iaxx, t.Iayy, t.Iazz, t.mc, t.Icxx, t.Icyy, t.Iczz, t.mbe, t.mbe * t.l5,
                     t.Ibexx, t.Ibeyy, t.Ibezz, t.mdf, t.mdf * t.l6, t.Idfxx, t.Idfyy, t.Idfzz,
                     t.Ibaseyy, CONFIG.actuation.motor.rotor_inertia])


def truth_overrides():
    """The simulated device as --params keys: its report parameters and its friction."""
    return {**pz.overrides(true_x(), CONFIG), "actuation.friction.viscous": VISCOUS,
            "actuation.friction.coulomb": COULOMB}


LAB_RATE = 1000.0
#: The working posture the lab's motion is centred on (rad): inside every stop.
LAB_POSTURE = np.array([0.0, 0.3, 0.45])


@functools.cache
def lab_prior():
    """The prior a lab identifies on: the shipped model (one Phantom for every test module)."""
    return Phantom()


def sum_of_sines(duration, amplitude, seed, sines=5, band=(0.1, 1.0)):
    """A lab's excitation: per joint, ``sines`` sines of seeded frequencies in ``band`` (Hz) and
    phases, each of amplitude ``amplitude`` / sines (rad), around LAB_POSTURE; (t, theta, dtheta,
    ddtheta) at LAB_RATE over ``duration`` (s), the rates and accelerations exact."""
    rng = np.random.default_rng(seed)
    t = np.arange(int(round(duration * LAB_RATE)) + 1) / LAB_RATE
    w = 2 * np.pi * rng.uniform(*band, (3, sines))
    arg = w * t[:, None, None] + rng.uniform(0, 2 * np.pi, (3, sines))
    a = amplitude / sines
    return t, LAB_POSTURE + a * np.sin(arg).sum(-1), a * (w * np.cos(arg)).sum(-1), -a * (w**2 * np.sin(arg)).sum(-1)


def lab_log(device, duration, amplitude, seed):
    """The device tracking a sum of sines with the prior's torques as feed-forward (a lab knows
    only its model), torque noise 1 % of the feed-forward's RMS, the encoder's angles."""
    t, theta, dtheta, ddtheta = sum_of_sines(duration, amplitude, seed)
    assert (CONFIG.limits.slack(theta) > 0.05).all()            # inside every stop
    tau = lab_prior().inverse_dynamics(theta, dtheta, ddtheta) + CONFIG.actuation.friction.torque(dtheta)
    return simulation.track(device, t, theta, dtheta, tau, torque_noise=0.01 * float(np.sqrt((tau**2).mean())),
                            seed=seed)


@functools.cache
def truth_log(duration, amplitude, seed):
    """lab_log of the device of truth_overrides(), simulated once per arguments (the wide log is
    test_prior's and test_timing's; conftest.GROUPS keeps both modules on one worker)."""
    return lab_log(Device(Phantom(describe(overrides=truth_overrides()))), duration, amplitude, seed)


def error(beta, truth, states):
    """The rigid-body torques of the base parameters ``beta`` (friction dropped) at ``states``
    against the device's own inverse dynamics: RMS error per joint as a share of the torque RMS."""
    phi, tau0 = General(lab_prior()).regressor_of(*states)
    rigid = np.concatenate([beta[:-6], np.zeros(6)])
    true = truth.inverse_dynamics(*states)
    return np.sqrt(((phi @ rigid + tau0 - true) ** 2).mean(axis=0) / (true**2).mean(axis=0))
