"""The generated C header (phantom_pin.codegen): compiled strictly as C99 and C++17, loaded
through ctypes, and compared function by function with Pinocchio through Phantom's API on every
shipped model and on an identified-style overlay; the committed headers are fresh; bad input
is refused and nothing is written."""

import ctypes
import functools
import shutil
import subprocess

import numpy as np
import pinocchio as pin
import pytest

from phantom_pin import Device, Phantom, describe, simulate
from phantom_pin.cli import main
from phantom_pin.codegen import header, write_header
from phantom_pin.codegen.generate import committed_header
from phantom_pin.config import MODELS, models
from phantom_pin.config.sampling import random_states
from phantom_pin.exceptions import InvalidInputError, PhantomPinError

#: Relative tolerance per state: max |C - Pinocchio| / max |Pinocchio| of each output.
TOLERANCE = 1e-12
N_STATES = 1000
#: An identified-style overlay on the CAD model: masses, centres of mass off the links' axes and
#: products of inertia, as `phantom-pin identify` writes them (links.NAME.{mass,com.k,inertia.xy}),
#: each a number the CAD already has nonzero (a zero made nonzero doubles SymPy's work: 7.5 s of CPU
#: against 3.5 s, for the same code paths).
OVERLAY = {"links.forearm_link.com.0": 3.1e-05, "links.forearm_link.mass": 0.028,
           "links.turret_link.inertia.xz": -1.9e-04, "links.lower_bar_link.com.0": 0.1012,
           "links.crank_link.inertia.xy": 3.5e-06, "links.upper_arm_link.com.1": 0.0022,
           "links.upper_arm_link.inertia.yz": 3e-6, "links.crank_link.mass": 0.2}
CASES = [(name, None) for name in models()] + [("premium_1_5_cad", OVERLAY)]
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
#: The header of a model with a stylus gimbal: its pose, (p, R) as 12 numbers per state.
STYLUS_SHIM = "LOOP(stylus_pose, phantom_stylus_pose(a + 3 * k, b + 3 * k, out + 12 * k, out + 12 * k + 3))\n"


@functools.cache
def _generated(name, prefix, overlay):
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


def per_state_error(actual, expected):
    """The largest over states of max |actual - expected| / max |expected| (each (n, k))."""
    return float((np.abs(actual - expected).max(axis=1) / np.abs(expected).max(axis=1)).max())


@pytest.mark.parametrize("name, overlay", CASES, ids=[n if o is None else f"{n}+overlay" for n, o in CASES])
def test_every_function_matches_pinocchio(name, overlay, tmp_path):
    """Each function of the header, compiled with -Werror as C99 and C++17, equals Phantom's
    (Pinocchio's) to 1e-12 relative per state over 1000 seeded states inside the stops."""
    description = describe(name, overrides=overlay) if overlay else describe(name)
    library = build(generated(name, overrides=overlay), tmp_path)
    phantom = Phantom(description)
    theta, dtheta, ddtheta = random_states(description.config.limits, N_STATES, seed=30)
    force = np.random.default_rng(31).normal(0, 2, (N_STATES, 3))
    pose = phantom.forward_kinematics(theta)
    jacobian = pose[:, :3, :3] @ phantom.body_jacobian(theta)[:, :3]  # the tip's velocity in s
    expected = {
        "gravity": phantom.gravity(theta),
        "inverse_dynamics": phantom.inverse_dynamics(theta, dtheta, ddtheta),
        "mass_matrix": phantom.mass_matrix(theta).reshape(-1, 9),
        "coriolis": np.einsum("nij,nj->ni", phantom.coriolis_matrix(theta, dtheta), dtheta),
        "tip_position": pose[:, :3, 3],
        "tip_jacobian": jacobian.reshape(-1, 9),
        "jacobian_transpose_force": np.einsum("nij,ni->nj", jacobian, force),
    }
    inputs = {"inverse_dynamics": (dtheta, ddtheta), "coriolis": (dtheta,), "jacobian_transpose_force": (force,)}
    errors = {}
    for function, reference in expected.items():
        actual = call(library, function, reference.shape[1], theta, *inputs.get(function, ()))
        errors[function] = per_state_error(actual, reference)
    assert max(errors.values()) <= TOLERANCE, errors
    mass = call(library, "mass_matrix", 9, theta).reshape(-1, 3, 3)
    assert np.array_equal(mass, mass.transpose(0, 2, 1))  # symmetric by construction


def test_the_stylus_pose_matches_phantom_and_pinocchio_on_the_touch_urdf(tmp_path):
    """The Touch header's stylus_pose, compiled with -Werror as C99 and C++17, equals
    Phantom.stylus_pose and, independently of Phantom's model rooted at frame s, Pinocchio's
    placement of the URDF frame stylus relative to report_s (oMf, the committed Touch URDF with
    its mimic joints) to 1e-12 (m and rotation entries) over 1000 seeded states, theta inside
    the stops and the gimbal inside its ranges; R is a rotation. The headers of the models
    without a gimbal have no such function."""
    description = describe("touch")
    library = build(generated("touch"), tmp_path, SHIM + STYLUS_SHIM)
    theta = random_states(description.config.limits, N_STATES, seed=32)[0]
    gimbal_range = description.config.gimbal
    gimbal = np.random.default_rng(33).uniform(gimbal_range.lower, gimbal_range.upper, (N_STATES, 3))
    out = call(library, "stylus_pose", 12, theta, gimbal)
    position, rotation = out[:, :3], out[:, 3:].reshape(-1, 3, 3)
    phantom = Phantom(description).stylus_pose(theta, gimbal)
    model = pin.buildModelFromXML(MODELS["touch"].urdf.read_text(), mimic=True)
    data = model.createData()
    index = [model.joints[model.getJointId(f"joint{j}")].idx_q for j in range(1, 7)]
    s, stylus = model.getFrameId("report_s"), model.getFrameId("stylus")
    urdf = np.empty((N_STATES, 4, 4))
    for k, angles in enumerate(np.hstack([theta, gimbal])):
        q = pin.neutral(model)
        q[index] = angles
        pin.framesForwardKinematics(model, data, q)
        urdf[k] = (data.oMf[s].inverse() * data.oMf[stylus]).homogeneous
    for reference in (phantom, urdf):
        assert np.abs(position - reference[:, :3, 3]).max() <= TOLERANCE
        assert np.abs(rotation - reference[:, :3, :3]).max() <= TOLERANCE
    assert np.abs(rotation @ rotation.transpose(0, 2, 1) - np.eye(3)).max() < 1e-14
    assert np.abs(np.linalg.det(rotation) - 1).max() < 1e-14
    for name in ("premium_1_5", "premium_1_5_cad"):
        assert "_stylus_pose" not in generated(name)


def test_openhaptics_helpers_follow_the_published_conventions(tmp_path):
    """The header's OpenHaptics conversions against the published conventions written out here,
    not against phantom_pin.interfaces.conventions (the same convention twice). Angles: Ubitrack/
    component_haptic_calibration's PhantomForwardKinematics.h lines 101-103 put the tip of
    OpenHaptics' angles a at x = -(l1 c2 + l2 s3) s1, y = l1 s2 - l2 c3 + l2, z = -l1 + (l1 c2 +
    l2 s3) c1 (l1 = l2 = 133.35 mm, its default): the header's tip at theta_from_openhaptics(a)
    is there (1e-12 m), and theta = (-a1, a2, a3) exactly. Torques: SensAble's CommandJointTorque
    sample gives HD_CURRENT_JOINT_TORQUE in mN m on OpenHaptics' own angles, so it does tau's
    power on their rates (1e-9 relative) and equals 1000 (-tau1, tau2, tau3) exactly; a spring
    restoring theta is the sample's restoring spring, torque = k (0 - a) with k > 0."""
    library = build(generated("touch"), tmp_path)
    rng = np.random.default_rng(5)
    angles = rng.uniform([-0.98, 0.0, 0.0], [0.98, 1.75, 2.0], (50, 3))   # inside the Touch's stops
    theta = call(library, "theta_from_openhaptics", 3, angles)
    assert np.array_equal(theta, np.column_stack([-angles[:, 0], angles[:, 1], angles[:, 2]]))
    length = 0.13335
    s1, c1, s2, c2, s3, c3 = (f(angles[:, k]) for k in range(3) for f in (np.sin, np.cos))
    ubitrack = np.column_stack([-(length * c2 + length * s3) * s1, length * s2 - length * c3 + length,
                                -length + (length * c2 + length * s3) * c1])
    assert np.abs(call(library, "tip_position", 3, theta) - ubitrack).max() < 1e-12
    tau, rates = rng.normal(0, 1, (50, 3)), rng.normal(0, 1, (50, 3))   # N m; OpenHaptics' angle rates
    torque = call(library, "openhaptics_torque_from_tau", 3, tau)
    assert np.array_equal(torque, 1000 * np.column_stack([-tau[:, 0], tau[:, 1], tau[:, 2]]))
    theta_rates = np.column_stack([-rates[:, 0], rates[:, 1], rates[:, 2]])   # d theta / dt of d a / dt
    power_mw = np.einsum("ni,ni->n", torque, rates)
    assert np.abs(power_mw - 1000 * np.einsum("ni,ni->n", tau, theta_rates)).max() < 1e-9 * np.abs(power_mw).max()
    restoring = call(library, "openhaptics_torque_from_tau", 3, -0.5 * theta)   # a spring to theta = 0
    assert np.all(restoring * angles <= 0) and np.all(restoring[angles != 0] != 0)  # the sample's: to a = 0


@pytest.mark.parametrize("name", models())
def test_committed_headers_are_fresh(name):
    """Each shipped model's committed header is what its configuration generates now."""
    assert committed_header(name).read_text() == generated(name), \
        f"{name}: run phantom-pin codegen --model {name} -o {committed_header(name)} --force"


def test_the_banner_names_model_source_and_overlay():
    text = header("premium_1_5_cad", prefix="lab_arm", overrides=OVERLAY)    # the generation of CASES' overlay
    banner = text[:text.index("*/")]
    assert "Model: premium_1_5_cad" in banner
    assert "Configuration: robots/phantom_description/config/premium_1_5_cad" in banner
    assert "Overlay: links.crank_link.inertia.xy = 3.5e-06; links.crank_link.mass = 0.2;" in banner
    assert "static inline void lab_arm_gravity(const double theta[3], double tau[3])" in text
    assert "phantom_gravity" not in text and "PHANTOM_MODEL_H" not in text


def test_bad_input_is_refused_with_describes_line(tmp_path):
    """header() raises describe()'s own error; a prefix that is not a C identifier is named."""
    with pytest.raises(Exception) as described:
        describe("touch", overrides={"links.forearm_link.mass": -1.0})
    with pytest.raises(type(described.value)) as generated:
        header("touch", overrides={"links.forearm_link.mass": -1.0})
    assert str(generated.value) == str(described.value)
    for prefix in ("1abc", "a-b", "", "é", "a b"):
        with pytest.raises(InvalidInputError) as error:
            header("touch", prefix=prefix)
        assert error.value.argument == "prefix"


def test_the_writer_never_overwrites_without_force(tmp_path):
    target = tmp_path / "model.h"
    write_header("one", target)
    with pytest.raises(InvalidInputError):
        write_header("two", target)
    assert target.read_text() == "one"
    write_header("two", target, force=True)
    assert target.read_text() == "two"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["model.h"]  # no temporary left


def test_cli_writes_the_header_and_refuses_bad_input(tmp_path, capsys):
    """phantom-pin codegen: the header of --model with --set and --prefix; on bad input one
    line naming the option, exit 2, and no file."""
    out = tmp_path / "arm.h"
    assert main(["codegen", "--model", "touch", "--prefix", "arm", "-o", str(out)]) == 0
    assert out.read_text() == generated("touch", prefix="arm")
    assert main(["codegen", "--model", "touch", "-o", str(out)]) == 2
    assert "--force" in capsys.readouterr().err
    assert out.read_text() == generated("touch", prefix="arm")
    bad = tmp_path / "bad.h"
    assert main(["codegen", "--model", "touch", "--prefix", "9lives", "-o", str(bad)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("phantom-pin: error: --prefix:") and err.count("\n") == 1
    assert main(["codegen", "--model", "touch", "--set", "links.forearm_link.mass=-1", "-o", str(bad)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert main(["info", "--model", "touch", "--set", "links.forearm_link.mass=-1"]) == 2
    assert capsys.readouterr().err == err  # the same line as any command's describe()
    assert not bad.exists()
    sets = [argument for key, value in OVERLAY.items() for argument in ("--set", f"{key}={value!r}")]
    assert main(["codegen", "--model", "premium_1_5_cad", *sets, "-o", str(out), "--force"]) == 0
    assert out.read_text() == generated("premium_1_5_cad", overrides=OVERLAY)  # --set as overrides=



@pytest.mark.parametrize("name", ["premium_1_5", "touch"])
def test_servo_loop_example_closes_the_loop_like_simulate(name, tmp_path):
    """examples/servo_loop.c, compiled strictly against the committed header, runs gravity
    compensation plus a joint spring at 1 kHz on the header's plant (RK4, one step per
    period): its log equals simulate()'s (Pinocchio's plant, the same controller in Python,
    no friction, stops nor saturation) to 1e-12 rad and N m, and the arm settles on the
    spring's rest posture."""
    include = committed_header(name)
    subprocess.run([*STRICT_C, "-O2", f"-I{include.parent}", f'-DPHANTOM_HEADER="{include.name}"',
                    str(include.parents[3] / "examples" / "servo_loop.c"), "-o", str(tmp_path / "servo"), "-lm"],
                   check=True, capture_output=True, text=True)
    run = subprocess.run([str(tmp_path / "servo")], check=True, capture_output=True, text=True).stdout
    log = np.array([[float(x) for x in line.split()] for line in run.splitlines()])
    phantom = Phantom.from_model(name)
    rest, stiffness, damping = np.array([0.3, 0.5, 0.9]), 1.0, 0.05  # as in servo_loop.c

    def controller(t, theta, dtheta):
        return phantom.gravity(theta) + stiffness * (rest - theta) - damping * dtheta
    result = simulate(np.array([0.0, 0.2, 0.6]), 1.0, controller, friction=False, hard_stops=False,
                      saturation=False, substeps=1, device=Device(phantom))
    assert np.array_equal(log[:, 0], result.t)
    assert np.abs(log[:, 1:4] - result.theta).max() <= 1e-12
    assert np.abs(log[:, 4:] - result.tau_commanded).max() <= 1e-12
    assert np.abs(log[-1, 1:4] - rest).max() < 2e-3


def test_without_sympy_one_line_names_the_package(monkeypatch, tmp_path, capsys):
    """Without SymPy (the codegen extra) header() and the command refuse in one line naming
    the package, and write nothing."""
    from phantom_pin.codegen import generate
    monkeypatch.setattr(generate, "sp", None)
    with pytest.raises(PhantomPinError, match="needs the package sympy"):
        header("touch")
    assert main(["codegen", "--model", "touch", "-o", str(tmp_path / "a.h")]) == 2
    err = capsys.readouterr().err
    assert "sympy" in err and err.count("\n") == 1
    assert not (tmp_path / "a.h").exists()


def test_a_missing_config_folder_is_blamed_on_config(tmp_path, capsys):
    assert main(["codegen", "--config", str(tmp_path / "none"), "-o", str(tmp_path / "a.h")]) == 2
    assert capsys.readouterr().err.startswith("phantom-pin: error: --config: ")
    assert not (tmp_path / "a.h").exists()


def test_an_overlays_banner_is_wrapped_into_short_comment_lines():
    """L10: identify's overlay sets dozens of keys; the banner lists each, in lines of at most
    100 characters (it was one line of 3,400), and the header still compiles (-Werror)."""
    text = generated("premium_1_5_cad", overrides=OVERLAY)
    overlay = text.split(" * Overlay: ")[1].split(" * Gravity:")[0].splitlines()
    assert len(overlay) > 1 and max(len(line) for line in overlay) <= 100
    flat = " ".join(line.strip(" *") for line in overlay)
    assert all(f"{key} = {value!r}" in flat for key, value in OVERLAY.items())


#: The servo loop's own terms (docs/servo-loop.md, "In your servo loop"): per state a, b = angles.
SERVO_SHIM = """#include "model.h"
void servo(int n, const double *a, const double *g, const double *r, double *out) {
    int k; for (k = 0; k < n; ++k) {
        phantom_openhaptics_force(a + 3 * k, g + 3 * k, out + 12 * k);
        phantom_openhaptics_joint_torque(a + 3 * k, g + 3 * k, out + 12 * k + 3);
        phantom_openhaptics_force_friction(a + 3 * k, g + 3 * k, r + 3 * k, out + 12 * k + 6);
        phantom_openhaptics_joint_torque_friction(a + 3 * k, g + 3 * k, r + 3 * k, out + 12 * k + 9); } }
"""


@pytest.mark.parametrize("name", models())
def test_the_servo_loop_functions_compensate_gravity_and_friction(name, tmp_path):
    """NAME_openhaptics_force and _joint_torque (and their _friction forms), compiled strictly,
    on 200 seeded states inside the stops (the Touch's gimbal inside its ranges, OpenHaptics'
    angles a = (-theta1, theta2, theta3)): J^T F and the joint torques on theta equal the
    gravity of references independent of Phantom (tests/references/openhaptics.py: the closed
    form, the CAD's re-derivation, the Touch's six-joint URDF in Pinocchio) to 1e-9 N m, plus the
    friction law (actuation.yaml's numbers) at the rates given; NAME_STYLUS says whether the
    model has a gimbal."""
    from references.openhaptics import gravity_and_jacobian
    text = generated(name)
    library = build(text, tmp_path, SERVO_SHIM)
    config = describe(name).config
    n = 200
    theta = random_states(config.limits, n, seed=61)[0]
    rng = np.random.default_rng(62)
    gimbal = np.zeros((n, 3)) if config.gimbal is None else \
        rng.uniform(config.gimbal.lower, config.gimbal.upper, (n, 3))
    rates = rng.normal(0, 1, (n, 3))
    sign = np.array([-1.0, 1.0, 1.0])
    out = np.empty((n, 12))
    pointer = ctypes.POINTER(ctypes.c_double)
    arrays = [np.ascontiguousarray(x) for x in (sign * theta, gimbal, rates)]
    library.servo(ctypes.c_int(n), *(x.ctypes.data_as(pointer) for x in arrays), out.ctypes.data_as(pointer))
    law = config.actuation.friction
    for k in range(n):
        gravity, jacobian = gravity_and_jacobian(name, theta[k], None if config.gimbal is None else gimbal[k])
        friction = np.array(law.viscous) * sign * rates[k] + np.array(law.coulomb) * np.sign(sign * rates[k])
        assert np.abs(jacobian.T @ out[k, :3] - gravity).max() <= 1e-9
        assert np.abs(sign * out[k, 3:6] / 1000 - gravity).max() <= 1e-9
        assert np.abs(jacobian.T @ out[k, 6:9] - gravity - friction).max() <= 1e-9
        assert np.abs(sign * out[k, 9:12] / 1000 - gravity - friction).max() <= 1e-9
    assert f"#define PHANTOM_STYLUS {int(config.gimbal is not None)}" in text


TRANSPARENT_SHIM = """#include "model.h"
void transparent(int n, const double *a, double kappa, double dead_band, double *out) {
    phantom_estimator e; const double g[3] = {0.0, 0.0, 0.0}; int k;
    phantom_estimator_init(&e, 1000.0, 20.0);
    for (k = 0; k < n; ++k) {
        phantom_estimator_update(&e, a + 3 * k);
        phantom_openhaptics_joint_torque_transparent(a + 3 * k, g, &e, kappa, dead_band, out + 3 * k); } }
"""


@pytest.mark.parametrize("name", models())
def test_the_transparent_joint_torque_is_the_compensators(name, tmp_path):
    """The header's estimator and NAME_openhaptics_joint_torque_transparent, over 300 ticks of a
    seeded smooth motion (OpenHaptics' angles, 1 kHz, with a pause the dead band must see), give
    the pyOpenHaptics Compensator's joint torques with gravity, friction and kappa = 0.5 of the
    inertia, tick by tick, to 1e-9 relative: one estimator and one law in two languages (the
    stylus at locked_at, where the header's M and C hold)."""
    from phantom_pin.interfaces.openhaptics import Compensator
    library = build(generated(name), tmp_path, TRANSPARENT_SHIM)
    t = np.arange(300) / 1000.0
    rng = np.random.default_rng(71)
    base, amplitude = np.array([0.1, 0.4, 0.5]), rng.uniform(0.05, 0.2, 3)
    angles = base + amplitude * np.sin(2 * np.pi * 1.5 * np.minimum(t, 0.15)[:, None] + rng.uniform(0, 1, 3))
    out = np.empty((len(t), 3))
    pointer = ctypes.POINTER(ctypes.c_double)
    a = np.ascontiguousarray(angles)
    library.transparent(ctypes.c_int(len(t)), a.ctypes.data_as(pointer), ctypes.c_double(0.5), ctypes.c_double(0.01),
                        out.ctypes.data_as(pointer))
    compensate = Compensator(name, "joint_torque", ("gravity", "friction", "inertia"), kappa=0.5)
    gimbal = None if describe(name).config.gimbal is None else [0.0, 0.0, 0.0]
    python = np.array([compensate.torque(x, gimbal) for x in angles]) * np.array([-1.0, 1.0, 1.0]) * 1000.0
    assert np.abs(out - python).max() <= 1e-9 * np.abs(python).max()
    assert np.abs(out[200:] - out[-1]).max() < np.abs(out[100:150] - out[-1]).max()   # the pause: inertia off
