"""The configuration premium_1_5_cad (mahilab/Phantom's CAD mass properties) against an
independent SymPy derivation in mahilab's own DH frames (tests/references/cad.py), at seeded
states inside the stops: (a) a numeric model built by hand in Pinocchio from the YAML of
robots/phantom_description/config/premium_1_5_cad, (b) phantom_pin.Phantom.from_model("premium_1_5_cad")."""

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
import yaml

from references.cad import gravity, mass_matrix

FOLDER = Path(__file__).resolve().parents[2] / "robots/phantom_description/config/premium_1_5_cad"
JOINTS = ("joint1", "joint2", "joint3")
N, SEED, TOLERANCE = 200, 20261123, 1e-9


def _yaml(name: str) -> dict:
    return yaml.safe_load((FOLDER / name).read_text())


def _thetas() -> np.ndarray:
    """N seeded postures (rad) in the joint box with the coupled stops."""
    lim = _yaml("joint_limits.yaml")
    lower, upper = (np.array([lim[j][k] for j in JOINTS]) for k in ("lower", "upper"))
    stops = lim["stops"]
    rng, out = np.random.default_rng(SEED), []
    while len(out) < N:
        t = rng.uniform(lower, upper)
        if t[1] - t[2] <= stops["theta2_minus_theta3_max"] and t[2] - t[1] <= stops["theta3_minus_theta2_max"]:
            out.append(t)
    return np.array(out)


def _relative(actual: np.ndarray, expected: np.ndarray) -> float:
    return float(np.abs(actual - expected).max() / np.abs(expected).max())


def _pinocchio_from_yaml():
    """The five links of physical_parameters.yaml as a Pinocchio tree of five revolute joints,
    q = (theta1, theta2, theta3, theta2 - theta3, theta3 - theta2) = G theta: the lower bar
    hinged to the crank at its pin (0, 0, -l3), the forearm hinged to the lower bar's far end
    (l1, 0, 0), so that their absolute angles are theta2 and theta3. Returns
    (M(theta), N(theta)) of the 3-DoF arm: G^T M_tree G + armature, G^T N_tree."""
    phys, kin, act = _yaml("physical_parameters.yaml"), _yaml("kinematics.yaml"), _yaml("actuation.yaml")
    model = pin.Model()
    model.gravity.linear = np.array([0.0, 0.0, -phys["gravity"]])
    down = np.array([0.0, -1.0, 0.0])
    tree = (("turret_link", 0, pin.JointModelRZ(), np.zeros(3)),
            ("upper_arm_link", 1, pin.JointModelRevoluteUnaligned(down), np.zeros(3)),
            ("crank_link", 1, pin.JointModelRevoluteUnaligned(down), np.zeros(3)),
            ("lower_bar_link", 3, pin.JointModelRevoluteUnaligned(down), np.array([0.0, 0.0, -kin["l3"]])),
            ("forearm_link", 4, pin.JointModelRevoluteUnaligned(down), np.array([kin["l1"], 0.0, 0.0])))
    for name, parent, joint, offset in tree:
        link = phys["links"][name]
        i = link["inertia"]
        tensor = np.array([[i["xx"], i["xy"], i["xz"]], [i["xy"], i["yy"], i["yz"]], [i["xz"], i["yz"], i["zz"]]])
        index = model.addJoint(parent, joint, pin.SE3(np.eye(3), offset), name)
        model.appendBodyToJoint(index, pin.Inertia(link["mass"], np.array(link["com"]), tensor), pin.SE3.Identity())
    data = model.createData()
    g = np.array([[1, 0, 0], [0, 1, 0], [0, 0, 1], [0, 1, -1], [0, -1, 1]], dtype=float)
    armature = np.diag([act["motor"]["rotor_inertia"] * act["transmission_ratio"][j] ** 2 for j in JOINTS])

    def m(theta):
        tree = pin.crba(model, data, g @ theta)       # crba fills the upper triangle
        return g.T @ (np.triu(tree) + np.triu(tree, 1).T) @ g + armature

    def n(theta):
        return g.T @ pin.computeGeneralizedGravity(model, data, g @ theta)

    return m, n


@pytest.fixture(scope="module")
def reference():
    thetas = _thetas()
    return thetas, np.array([mass_matrix(t) for t in thetas]), np.array([gravity(t) for t in thetas])


def test_the_yaml_links_equal_mahilabs_raw_cad_in_its_dh_frames(reference):
    """(a) The YAML's five links, in our frames, give mahilab's CAD dynamics with true rates."""
    thetas, ref_m, ref_n = reference
    m, n = _pinocchio_from_yaml()
    assert _relative(np.array([m(t) for t in thetas]), ref_m) < TOLERANCE
    assert _relative(np.array([n(t) for t in thetas]), ref_n) < TOLERANCE


def test_the_reference_is_symmetric_positive_definite_and_m23_has_no_constant_part(reference):
    """No body of the parallelogram turns with both theta2 and theta3, so M23 is the COM
    coupling of the forearm and the lower bar alone, l1 m_a (...) + l3 m_c (...) in
    cos/sin(theta2 - theta3): its mean over a turn of theta2 - theta3 is zero. mahilab's
    compute_energies.m rates put Ic_a.zz + Ic_c.zz = 1.9142e-4 kg m^2 there (docs/cad.md)."""
    _, ref_m, _ = reference
    assert np.allclose(ref_m, np.swapaxes(ref_m, 1, 2), rtol=0, atol=1e-18)
    assert np.linalg.eigvalsh(ref_m).min() > 0
    turn = np.linspace(0, 2 * np.pi, 64, endpoint=False)
    m23 = np.array([mass_matrix([0.3, d, 0.0])[1, 2] for d in turn])
    assert abs(m23.mean()) < 1e-12 * np.abs(m23).max()


def test_phantom_premium_1_5_cad_matches_the_reference(reference):
    """(b) The shipped model, through the package's own loading of the configuration."""
    from phantom_pin import Phantom

    thetas, ref_m, ref_n = reference
    phantom = Phantom.from_model("premium_1_5_cad")
    assert _relative(np.array([phantom.mass_matrix(t) for t in thetas]), ref_m) < TOLERANCE
    assert _relative(np.array([phantom.gravity(t) for t in thetas]), ref_n) < TOLERANCE


def test_the_cad_mjcf_in_mujoco_matches_the_reference(reference):
    """(c) MuJoCo's reading of the committed MJCF (armature, gravity 9.80665 m/s^2 as an option)."""
    import mujoco

    from helpers import MujocoArm
    from phantom_pin.config import MODELS
    from phantom_pin.dynamics.coupling import Coupling

    model = MODELS["premium_1_5_cad"]
    arm = MujocoArm(mujoco.MjModel.from_xml_path(str(model.mjcf)), Coupling(model.urdf.read_text()))
    assert arm.model.opt.gravity[2] == -9.80665
    thetas, ref_m, ref_n = reference
    reduced = [arm.reduced_mass_and_gravity(t) for t in thetas[:50]]
    assert _relative(np.array([m for m, _ in reduced]), ref_m[:50]) < TOLERANCE
    assert _relative(np.array([n for _, n in reduced]), ref_n[:50]) < TOLERANCE
