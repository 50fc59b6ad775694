"""device.plant.Plant, the simulator's plant, against the report's closed form (M, C, N) with the
friction and stop laws and mahilab/Phantom's constants written here; a stuck joint against the
Lagrange-multiplier form of the constraint (a 4x4 solve); the saturation clip against the data
sheet's torques. And the device layer's promise: no module reads another's private names or hides
an import of the package inside a function."""

import ast
import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from helpers import REPORT
from phantom_pin import Device, MissingDataError, closed_form, config
from phantom_pin.device.plant import Plant

DEG = math.pi / 180
K_STOP, B_STOP = 10.0, 0.1                       # N m/rad, N m s/rad (mahilab's hard stop)
VISCOUS, COULOMB = 5e-4, 0.01                    # N m s/rad, N m (mahilab's)
UPPER_1, COUPLED_MAX = 90 * DEG, 65 * DEG        # joint 1's upper stop, theta2 - theta3 <= 65 deg
RATIOS = np.array([13.3, 11.6, 11.6])            # the report (docs/errata.md E15)
TAU_NOMINAL, TAU_STALL = 28.6e-3, 129e-3         # N m, maxon RE 25 data sheet
ENCODER_CPR, QUADRATURE = 1024, 4                # HEDM-5500, decoded X4
DEVICE_DIR = Path(__file__).resolve().parents[2] / "phantom_pin" / "device"


@pytest.fixture(scope="module")
def device():
    return Device()


def plant(device, **options):
    settings = {"friction": True, "hard_stops": True, "saturation": True, "contact_step": 1e-3} | options
    return Plant(device, **settings)


def rhs(q, v, tau):
    """tau - C(q, v) v - N(q) (N m), the report's closed form."""
    return tau - closed_form.coriolis_matrix(q, v, REPORT) @ v - closed_form.gravity(q, REPORT)


@pytest.mark.parametrize("stop", ["joint 1", "coupled"])
def test_sliding_against_a_stop_is_the_closed_form_with_both_laws(device, stop):
    """All joints sliding, one stop penetrated: M a = tau - viscous v - coulomb sign(v) + the stop's
    -(K depth + B rate) along its coordinate."""
    if stop == "joint 1":
        q, gradient = np.array([UPPER_1 + 0.03, 0.3, 0.4]), np.array([1.0, 0.0, 0.0])
        depth = q[0] - UPPER_1
    else:
        q, gradient = np.array([0.2, 1.3, 0.1]), np.array([0.0, 1.0, -1.0])
        depth = q[1] - q[2] - COUPLED_MAX
    assert depth > 0
    v, tau = np.array([0.5, -0.3, 0.2]), np.array([0.05, -0.02, 0.03])
    stop_torque = -(K_STOP * depth + B_STOP * gradient @ v) * gradient
    expected = np.linalg.solve(closed_form.mass_matrix(q, REPORT),
                               rhs(q, v, tau) - VISCOUS * v - COULOMB * np.sign(v) + stop_torque)
    got = plant(device).acceleration(q.tolist(), v.tolist(), tau.tolist())
    np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-12)   # rad/s^2, measured 1.1e-13 on 613
    free = plant(device, hard_stops=False).acceleration(q.tolist(), v.tolist(), tau.tolist())
    assert np.abs(np.array(free) - expected).max() > 1e-3                # the stop does act


@pytest.mark.parametrize("stuck", [(0,), (1,), (2,), (1, 2)])
def test_stuck_joints_are_held_by_the_lagrange_multipliers_of_their_constraints(device, stuck):
    """Joints at rest, each loaded 0.004 N m past gravity (below the Coulomb torque): [[M, E],
    [E^T, 0]] [a; f] = [rhs; 0] (E their unit columns) gives their a = 0 and holding torques f
    within +-coulomb; the others slide (with joint 1 stuck, the coupled pair 2 and 3)."""
    q, v = np.array([0.1, 0.5, 0.6]), np.array([0.4, 0.35, -0.3])
    e = np.eye(3)[:, list(stuck)]
    v[list(stuck)] = 0.0
    tau = closed_form.gravity(q, REPORT) + 0.004 * e.sum(axis=1)
    force = rhs(q, v, tau) - VISCOUS * v - COULOMB * np.sign(v)
    kkt = np.block([[closed_form.mass_matrix(q, REPORT), e], [e.T, np.zeros((len(stuck), len(stuck)))]])
    solution = np.linalg.solve(kkt, np.concatenate([force, np.zeros(len(stuck))]))
    assert np.abs(solution[3:]).max() < COULOMB                         # the state sticks indeed
    got = plant(device).acceleration(q.tolist(), v.tolist(), tau.tolist())
    assert all(got[i] == 0.0 for i in stuck)
    np.testing.assert_allclose(got, solution[:3], rtol=1e-12, atol=1e-12)


def test_beyond_the_coulomb_torque_a_joint_at_rest_breaks_away_along_its_load(device):
    """Joint 2 at rest, loaded 0.02 N m past gravity (twice the Coulomb torque): it slides the way
    the load pushes, with the Coulomb friction against it."""
    q, v = np.array([0.1, 0.5, 0.6]), np.array([0.4, 0.0, -0.3])
    tau = closed_form.gravity(q, REPORT) + np.array([0.0, 0.02, 0.0])
    sign = np.sign(v) + np.array([0.0, 1.0, 0.0])
    expected = np.linalg.solve(closed_form.mass_matrix(q, REPORT), rhs(q, v, tau) - VISCOUS * v - COULOMB * sign)
    got = plant(device).acceleration(q.tolist(), v.tolist(), tau.tolist())
    assert got[1] > 0
    np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-12)


def test_hold_is_classical_rk4_of_the_closed_form_without_friction_and_stops(device):
    """One period of 1 ms in two RK4 steps under a held torque, against the classical RK4 of the
    report's closed form written here."""
    def rate(x, tau):
        q, v = x[:3], x[3:]
        return np.concatenate([v, np.linalg.solve(closed_form.mass_matrix(q, REPORT), rhs(q, v, tau))])

    x, tau, h = np.array([0.1, 0.5, 0.6, 0.4, -0.2, 0.3]), np.array([0.02, 0.05, -0.03]), 5e-4
    for _ in range(2):
        k1 = rate(x, tau)
        k2 = rate(x + h / 2 * k1, tau)
        k3 = rate(x + h / 2 * k2, tau)
        k4 = rate(x + h * k3, tau)
        x = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    got = plant(device, friction=False, hard_stops=False).hold([0.1, 0.5, 0.6], [0.4, -0.2, 0.3], tau.tolist(),
                                                               1e-3, 2)
    np.testing.assert_allclose(np.concatenate(got), x, rtol=0, atol=1e-15)   # rad, rad/s; measured 0
    one = plant(device, friction=False, hard_stops=False).hold([0.1, 0.5, 0.6], [0.4, -0.2, 0.3], tau.tolist(),
                                                               1e-3, 1)
    assert np.abs(np.concatenate(one) - x).max() > 1e-13                          # two steps are not one (3.5e-13)


def test_the_clip_is_the_data_sheet_torque_of_each_policy(device):
    command = [3.0, -3.0, 0.01]                    # N m, beyond both limits on joints 1 and 2
    continuous, peak = TAU_NOMINAL * RATIOS, TAU_STALL * RATIOS
    np.testing.assert_allclose(plant(device).saturate(command), [continuous[0], -continuous[1], 0.01], rtol=1e-15)
    np.testing.assert_allclose(plant(device, saturation="peak").saturate(command), [peak[0], -peak[1], 0.01],
                               rtol=1e-15)
    assert plant(device, saturation=False).saturate(command) == command


def test_counts_per_radian_are_the_encoder_and_the_ratios(device):
    np.testing.assert_allclose(device.counts_per_radian, ENCODER_CPR * QUADRATURE * RATIOS / (2 * math.pi),
                               rtol=1e-15)
    with pytest.raises(MissingDataError) as raised:
        _ = Device.from_model("touch").counts_per_radian
    assert raised.value.argument == "counts_per_radian"


def test_the_device_modules_keep_to_their_own_private_names_and_import_at_the_top():
    """No attribute starting with one underscore read from anything but self or cls (another
    class's private state), and no function-local import of phantom_pin (a hidden cycle)."""
    found = []
    for path in sorted(DEVICE_DIR.glob("*.py")):
        tree = ast.parse(path.read_text())
        for node in ast.walk(tree):
            if isinstance(node, ast.Attribute) and node.attr.startswith("_") and not node.attr.startswith("__") \
                    and not (isinstance(node.value, ast.Name) and node.value.id in ("self", "cls")):
                found.append(f"{path.name}:{node.lineno} reads .{node.attr}")
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                for inner in ast.walk(node):
                    names = [inner.module or ""] if isinstance(inner, ast.ImportFrom) else \
                        [alias.name for alias in inner.names] if isinstance(inner, ast.Import) else []
                    if any(name.split(".")[0] == "phantom_pin" for name in names):
                        found.append(f"{path.name}:{inner.lineno} imports inside {node.name}")
    assert found == []


# -- stiction: which joint breaks away, where and when; the substeps; divergence ----------------


def _plant(overrides=None, **options):
    from phantom_pin import Device, Phantom, describe
    from phantom_pin.device.plant import Plant

    device = Device(Phantom(describe(overrides=overrides or {})))
    settings = {"friction": True, "hard_stops": False, "saturation": False, "contact_step": 1e-3} | options
    return device, Plant(device, **settings)


def test_of_the_joints_stuck_at_rest_the_most_overloaded_breaks_away_first():
    """Of the joints stuck at rest, the most overloaded (holding torque less its Coulomb torque)
    breaks away first, not the most loaded. The rule written here on Phantom's M and gravity
    (the holding torques of the stuck joints, M_SL a_L - rhs_S with the sliding ones' Coulomb
    friction), at 300 seeded postures and loads at rest with Coulomb torques (0.1, 0.45, 0.1) N m:
    the plant's stuck joints (zero acceleration) and sliding directions are the rule's; the most
    loaded first would differ at a share of them."""
    coulomb = (0.1, 0.45, 0.1)
    device, plant = _plant({f"actuation.friction.coulomb.joint{j + 1}": c for j, c in enumerate(coulomb)})
    phantom = device.phantom

    def modes(q, tau, overload):
        mass, gravity, mode = phantom.mass_matrix(np.array(q)), phantom.gravity(np.array(q)), [0, 0, 0]
        while 0 in mode:
            free, stuck = [i for i in range(3) if mode[i]], [i for i in range(3) if not mode[i]]
            rhs = np.array(tau) - gravity - np.array(coulomb) * mode
            a = np.zeros(3)
            if free:
                a[free] = np.linalg.solve(mass[np.ix_(free, free)], rhs[free])
            holding = mass[stuck] @ a - rhs[stuck]
            k = max(range(len(stuck)), key=lambda k: abs(holding[k]) - (coulomb[stuck[k]] if overload else 0))
            if abs(holding[k]) < coulomb[stuck[k]]:
                break
            mode[stuck[k]] = -1 if holding[k] > 0 else 1
        return mode

    rng, differ = np.random.default_rng(5), 0
    for _ in range(300):
        q = [0.0, rng.uniform(0.1, 1.0), rng.uniform(0.2, 1.5)]
        tau = (phantom.gravity(np.array(q)) - [0.0, *rng.uniform(-0.6, 0.6, 2)]).tolist()
        got = [int(np.sign(a)) for a in plant.acceleration(q, [0.0] * 3, tau)]
        assert got == modes(q, tau, True), (q, tau)
        differ += modes(q, tau, False) != got
    assert differ > 30


def test_a_joint_that_breaks_away_within_a_step_is_released_there():
    """A joint that breaks away within a step is released there (the stick-to-slip event), not at
    the step's end. Joint 2 at rest held 0.0022 N m past gravity (below its 0.01 N m Coulomb
    torque at the start), joint 3 driven: as joint 3 sweeps, the torque holding joint 2 crosses
    the Coulomb torque within the 20 ms step. One step of 20 ms equals 2000 steps of 10 us (whose
    own lateness is 10 us) within 1e-5 rad/s; a step that ignored the breakaway ends with joint 2
    still at rest."""
    device, plant = _plant()
    q = [0.0, 0.5, 0.9]
    tau = (device.phantom.gravity(np.array(q)) + [0.0, -0.0022, 0.05]).tolist()
    assert plant.acceleration(q, [0.0] * 3, tau)[1] == 0.0        # stuck at the start
    coarse, fine = plant.hold(q, [0.0] * 3, tau, 0.02, 1), plant.hold(q, [0.0] * 3, tau, 0.02, 2000)
    assert fine[1][1] < -3e-4                                         # broken away by the end
    np.testing.assert_allclose(coarse[1], fine[1], rtol=0, atol=1e-5)
    np.testing.assert_allclose(coarse[0], fine[0], rtol=0, atol=1e-7)


@pytest.mark.parametrize("share, slides", [(1.05, True), (0.95, False)])
def test_a_joint_at_rest_breaks_away_at_its_coulomb_torque(share, slides):
    """A joint at rest breaks away at its Coulomb torque: joint 1 (no gravity) at rest under
    gravity compensation plus share x its Coulomb torque (0.01 N m, as actuation.yaml states it)
    slides beyond it, sticks below."""
    stated = yaml.safe_load((config.MODELS["premium_1_5"].config / "actuation.yaml").read_text())["friction"]
    device, plant = _plant()
    q = [0.2, 0.5, 0.7]
    tau = (device.phantom.gravity(np.array(q)) + [share * stated["coulomb"], 0.0, 0.0]).tolist()
    assert (plant.acceleration(q, [0.0] * 3, tau)[0] > 0) == slides


def test_the_contact_substeps_follow_the_largest_viscous_coefficient():
    """The contact substeps follow the largest of the joints' viscous coefficients:
    contact_substeps' documented rule, period x (3 B + max viscous) / m / 0.7 rounded up, m half
    the smallest eigenvalue of M(theta0), with joint 3's viscous 5 N m s/rad (joint 1's the
    shipped 5e-4) and without stops, where the damping alone sets it."""
    from phantom_pin.device.plant import DAMPING_SCALE, contact_substeps

    device, _ = _plant({"actuation.friction.viscous.joint3": 5.0})
    theta0 = np.array([0.0, 0.5, 0.9])
    m = 0.5 * np.linalg.eigvalsh(device.phantom.mass_matrix(theta0)).min()
    expected = int(np.ceil(1e-3 * 5.0 / m / DAMPING_SCALE))
    assert expected > 5
    assert contact_substeps(device, theta0, 1e-3, friction=True, hard_stops=False) == expected


def test_hold_raises_diverged_when_the_state_leaves_the_finite_numbers():
    """hold() raises Diverged when the state leaves the finite numbers (with friction, a 1e300 N m
    command), never NaN angles."""
    from phantom_pin.device.plant import Diverged

    _, plant = _plant()
    with pytest.raises(Diverged):
        plant.hold([0.0, 0.5, 0.9], [0.0] * 3, [1e300, 0.0, 0.0], 1e-3, 1)
