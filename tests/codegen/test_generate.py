"""The generated C header (phantom_pin.codegen): compiled strictly as C99 and C++17, loaded
through ctypes, and compared function by function with Pinocchio through Phantom's API on every
shipped model and on an identified-style overlay; the committed headers are fresh; bad input
is refused and nothing is written."""

import subprocess

import numpy as np
import pinocchio as pin
import pytest

from helpers import OVERLAY, SHIM, STRICT_C, build, call, generated
from phantom_pin import Device, Phantom, describe, simulate
from phantom_pin.cli import main
from phantom_pin.codegen import header
from phantom_pin.codegen.generate import committed_header
from phantom_pin.config import MODELS, models
from phantom_pin.config.sampling import random_states
from phantom_pin.exceptions import InvalidInputError, PhantomPinError

#: Relative tolerance per state: max |C - Pinocchio| / max |Pinocchio| of each output.
TOLERANCE = 1e-12
N_STATES = 1000
CASES = [(name, None) for name in models()] + [("premium_1_5_cad", OVERLAY)]

#: The header of a model with a stylus gimbal: its pose, (p, R) as 12 numbers per state.
STYLUS_SHIM = "LOOP(stylus_pose, phantom_stylus_pose(a + 3 * k, b + 3 * k, out + 12 * k, out + 12 * k + 3))\n"


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


def test_an_overlays_banner_is_wrapped_into_short_comment_lines():
    """L10: identify's overlay sets dozens of keys; the banner lists each, in lines of at most
    100 characters (it was one line of 3,400), and the header still compiles (-Werror)."""
    text = generated("premium_1_5_cad", overrides=OVERLAY)
    overlay = text.split(" * Overlay: ")[1].split(" * Gravity:")[0].splitlines()
    assert len(overlay) > 1 and max(len(line) for line in overlay) <= 100
    flat = " ".join(line.strip(" *") for line in overlay)
    assert all(f"{key} = {value!r}" in flat for key, value in OVERLAY.items())
