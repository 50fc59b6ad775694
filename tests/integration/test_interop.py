"""The committed URDF and MJCF in other tools: MuJoCo, Drake and urdfdom's check_urdf, for
every model written in the report's terms (premium_1_5 and touch: the closed form applies;
premium_1_5_cad has its own SymPy reference, tests/config/test_cad_model.py).

Each tool's dynamics are compared with the report's closed form (phantom_pin.report.closed_form),
projected to theta1..theta3 through the coupling matrix G read from the URDF's mimic tags
(v_tree = G dtheta): M = G^T M_tree G, N = G^T N_tree. Free swings are compared with an
RK4 integration of the closed form written here. States are seeded and inside the device's
limits: the URDF's joint box and the coupled stops of the configuration's joint_limits.yaml.
"""

import dataclasses
import warnings
from pathlib import Path

import mujoco
import numpy as np
import pydrake.all as drake
import pytest
import yaml

from helpers import ACTUATED, MujocoArm, inside_stops, relative_error
from phantom_pin import config
from phantom_pin.config.types import GIMBAL_JOINTS
from phantom_pin.dynamics.coupling import Coupling
from phantom_pin.report import closed_form
from references.gimbal import gimbal_gravity, gimbal_mass_matrix

THETA0 = np.array([0.3, 0.8, 0.4])  # rad, the free swing's rest state (inside every model's stops)
SWING = 0.5  # s of the free swing: every model turns a joint by more than 2.9 rad (measured)


@dataclasses.dataclass(frozen=True)
class Case:
    """A model written in the report's terms: its Config and report numbers, its folder and files."""
    name: str
    config: config.Config
    config_dir: Path
    urdf: Path
    mjcf: Path
    scene: Path

    @property
    def report(self):
        return self.config.report

    @property
    def locked(self) -> np.ndarray:
        """The gimbal angles (rad) at which a stylus gimbal is held (none without one)."""
        return np.array(self.config.gimbal.locked_at if self.config.gimbal else [], float)

    def full(self, theta: np.ndarray) -> np.ndarray:
        """The URDF's independent joints of theta: theta, then a gimbal at ``locked``."""
        return np.concatenate([theta, self.locked])

    def mass(self, theta: np.ndarray) -> np.ndarray:
        """The report's M (eqs 81-85), plus a locked stylus gimbal's share (gimbal_reference)."""
        extra = gimbal_mass_matrix(theta, self.locked) if len(self.locked) else 0.0
        return closed_form.mass_matrix(theta, self.report) + extra

    def gravity(self, theta: np.ndarray) -> np.ndarray:
        """The report's N (eqs 93-94), plus a locked stylus gimbal's (gimbal_reference)."""
        extra = gimbal_gravity(theta, self.locked) if len(self.locked) else 0.0
        return closed_form.gravity(theta, self.report) + extra

    def coriolis_force(self, theta: np.ndarray, dtheta: np.ndarray) -> np.ndarray:
        """C dtheta (N m): the report's (eqs 86-92), plus a locked gimbal's from its mass matrix
        by the Christoffel identity C dtheta = dM/dt dtheta - grad(dtheta^T M dtheta) / 2, dM
        by central differences (h = 1e-6 rad: 1e-12 relative)."""
        force = closed_form.coriolis_matrix(theta, dtheta, self.report) @ dtheta
        if not len(self.locked):
            return force
        h, slopes = 1e-6, []
        for k in range(3):
            e = np.eye(3)[k] * h
            ahead, behind = gimbal_mass_matrix(theta + e, self.locked), gimbal_mass_matrix(theta - e, self.locked)
            slopes.append((ahead - behind) / (2 * h))
        rate = sum(d * v for d, v in zip(slopes, dtheta))
        return force + rate @ dtheta - 0.5 * np.array([dtheta @ d @ dtheta for d in slopes])


#: The models the closed form describes.
REPORT_MODELS = [name for name in config.models() if config.read(name).report is not None]


@pytest.fixture(scope="module", params=REPORT_MODELS)
def case(request) -> Case:
    model = config.MODELS[request.param]
    return Case(model.name, config.read(model.name), model.config, model.urdf, model.mjcf, model.scene)


@pytest.fixture(scope="module")
def coupling(case) -> Coupling:
    return Coupling(case.urdf.read_text())


def rk4_closed_form(theta0: np.ndarray, duration: float, step: float, case: Case, damping: float = 0.0) -> np.ndarray:
    """theta (rad) after ``duration`` s of motion from rest under tau = -damping * dtheta
    (N m s/rad), RK4 on eq. 80 with the case's closed form (and its locked gimbal)."""
    def rate(x):
        theta, dtheta = x[:3], x[3:]
        force = -case.coriolis_force(theta, dtheta) - case.gravity(theta) - damping * dtheta
        return np.concatenate([dtheta, np.linalg.solve(case.mass(theta), force)])
    x = np.concatenate([theta0, np.zeros(3)])
    for _ in range(round(duration / step)):
        k1 = rate(x)
        k2 = rate(x + step / 2 * k1)
        k3 = rate(x + step / 2 * k2)
        k4 = rate(x + step * k3)
        x = x + step / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    return x[:3]


# -- MuJoCo ------------------------------------------------------------------------------

def test_mujoco_loads_the_committed_urdf_with_the_report_dynamics(case, coupling):
    arm = MujocoArm(mujoco.MjModel.from_xml_path(str(case.urdf)), coupling, case)
    arm.model.opt.gravity[:] = [0, 0, -case.config.gravity]  # a URDF has no g (MuJoCo's default: 9.81)
    assert arm.model.neq == 4  # the mimic tags, as joint equalities
    armature = np.diag(case.config.actuation.armature)  # the URDF has no armature
    for theta in inside_stops(200, seed=1, config_dir=case.config_dir):
        mass, gravity = arm.reduced_mass_and_gravity(theta)
        assert relative_error(mass, case.mass(theta) - armature) < 1e-9
        assert relative_error(gravity, case.gravity(theta)) < 1e-9


def test_no_self_contact_in_mujoco_inside_the_limits(case, coupling):
    """MuJoCo excludes only parent-child pairs: the geometry itself must stay apart."""
    for path in (case.urdf, case.scene):
        arm = MujocoArm(mujoco.MjModel.from_xml_path(str(path)), coupling, case)
        for theta in inside_stops(300, seed=2, config_dir=case.config_dir):
            arm.set(theta)
            pairs = {(arm.model.body(arm.model.geom_bodyid[c.geom1]).name,
                      arm.model.body(arm.model.geom_bodyid[c.geom2]).name)
                     for c in arm.data.contact[:arm.data.ncon]}
            assert not pairs, f"{path.name}: contact {pairs} at theta = {theta}"


def test_mjcf_has_the_report_dynamics_with_the_rotors(case, coupling):
    arm = MujocoArm(mujoco.MjModel.from_xml_path(str(case.mjcf)), coupling, case)
    for theta in inside_stops(200, seed=3, config_dir=case.config_dir):
        mass, gravity = arm.reduced_mass_and_gravity(theta)
        assert relative_error(mass, case.mass(theta)) < 1e-9
        assert relative_error(gravity, case.gravity(theta)) < 1e-9


def test_mjcf_tip_site_is_eq10(case, coupling):
    """The tip site, seen from the report_s site, is eq. 10's position (1e-12 m)."""
    arm = MujocoArm(mujoco.MjModel.from_xml_path(str(case.mjcf)), coupling, case)
    tip, s = arm.model.site("tip").id, arm.model.site("report_s").id
    for theta in inside_stops(100, seed=4, config_dir=case.config_dir):
        arm.set(theta)
        position = arm.data.site_xmat[s].reshape(3, 3).T @ (arm.data.site_xpos[tip] - arm.data.site_xpos[s])
        np.testing.assert_allclose(position, closed_form.forward_kinematics(theta, case.report)[:3, 3], atol=1e-12)


def test_mjcf_actuators_sensors_and_options_follow_the_yaml(case):
    """Motors at the motor shaft (gear = ratio, range = continuous torque, armature J r^2), or,
    without public motor data, at the joint (gear 1, range = joint_torque_limit, no armature)."""
    model = mujoco.MjModel.from_xml_path(str(case.mjcf))
    actuation = yaml.safe_load((case.config_dir / "actuation.yaml").read_text())
    settings = yaml.safe_load((case.config_dir / "mjcf.yaml").read_text())
    motor = actuation["motor"]
    for i, joint in enumerate(ACTUATED):
        assert model.joint(model.actuator_trnid[i, 0]).name == joint
        dof = model.jnt_dofadr[model.joint(joint).id]
        if motor is None:
            torque, gear, armature = actuation["joint_torque_limit"][joint], 1.0, 0.0
        else:
            torque, gear = motor["max_continuous_torque"], actuation["transmission_ratio"][joint]
            armature = motor["rotor_inertia"] * gear ** 2
        assert model.actuator_gear[i, 0] == gear
        np.testing.assert_array_equal(model.actuator_ctrlrange[i], [-torque, torque])
        assert model.dof_armature[dof] == pytest.approx(armature, rel=1e-15)
    for joint in ACTUATED:
        assert model.dof_damping[model.jnt_dofadr[model.joint(joint).id]] == actuation["friction"]["viscous"]
        assert model.dof_frictionloss[model.jnt_dofadr[model.joint(joint).id]] == actuation["friction"]["coulomb"]
    assert model.opt.timestep == settings["timestep"]
    assert model.opt.integrator == mujoco.mjtIntegrator.mjINT_RK4
    assert [model.sensor(i).name for i in range(model.nsensor)] == [
        *(f"{j}_pos" for j in ACTUATED), *(f"{j}_vel" for j in ACTUATED), "tip_pos"]


def test_mjcf_tendon_is_the_coupled_stops(case, coupling):
    """MuJoCo's tendon theta2 - theta3 limits exactly the postures outside the stops."""
    stops = yaml.safe_load((case.config_dir / "joint_limits.yaml").read_text())["stops"]
    model = mujoco.MjModel.from_xml_path(str(case.mjcf))
    arm = MujocoArm(model, coupling, case)
    limit = mujoco.mjtConstraint.mjCNSTR_LIMIT_TENDON
    rng = np.random.default_rng(6)
    lower, upper = model.jnt_range[:3].T
    for theta in rng.uniform(lower, upper, (300, 3)):
        arm.set(theta)
        difference = theta[1] - theta[2]
        assert arm.data.ten_length[0] == pytest.approx(difference, abs=1e-12)
        outside = (difference > stops["theta2_minus_theta3_max"]
                   or -difference > stops["theta3_minus_theta2_max"])
        assert (limit in arm.data.efc_type[:arm.data.nefc]) == outside, theta


def test_mjcf_free_swing_follows_the_closed_form(case, coupling):
    """SWING s from rest at THETA0 with RK4 at 1 ms (limits, contacts, friction, damping off)."""
    model = mujoco.MjModel.from_xml_path(str(case.mjcf))
    for flag in ("mjDSBL_LIMIT", "mjDSBL_CONTACT", "mjDSBL_FRICTIONLOSS", "mjDSBL_DAMPER"):
        model.opt.disableflags |= getattr(mujoco.mjtDisableBit, flag)
    arm = MujocoArm(model, coupling, case)
    arm.set(THETA0)
    for _ in range(round(SWING / model.opt.timestep)):
        mujoco.mj_step(model, arm.data)
    theta = arm.data.qpos[arm.qpos[:3]]
    # converged: 1e-3 s differs by 5e-10 rad (the gimbal's share, slower to evaluate, takes that)
    reference = rk4_closed_form(THETA0, SWING, 1e-3 if len(case.locked) else 1e-4, case)
    # a stylus gimbal's lock is a soft equality (solref 2 ms), which yields slightly under this
    # swing's accelerations: 8.1e-6 rad after 0.5 s, measured (1.1e-6 without a gimbal)
    assert np.abs(theta - reference).max() < (3e-5 if len(case.locked) else 1e-5)
    assert np.abs(theta - THETA0).max() > 1.0  # it did swing


# -- Drake -------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def drake_plant(case):
    builder = drake.DiagramBuilder()
    plant, _ = drake.AddMultibodyPlantSceneGraph(builder, time_step=1e-4)
    plant.set_discrete_contact_approximation(drake.DiscreteContactApproximation.kSap)
    with warnings.catch_warnings():  # Drake warns that it ignores mechanicalReduction
        warnings.simplefilter("ignore")
        drake.Parser(plant).AddModels(str(case.urdf))
    plant.WeldFrames(plant.world_frame(), plant.GetFrameByName("base_link"))
    plant.mutable_gravity_field().set_gravity_vector([0, 0, -case.config.gravity])  # a URDF has no g
    plant.Finalize()
    diagram = builder.Build()
    return plant, diagram


def _drake_positions(plant, coupling: Coupling) -> list[int]:
    return [plant.GetJointByName(n).position_start() for n in coupling.tree.names[1:]]


def test_drake_reads_the_mimic_tags_and_the_rotor_inertia(case, drake_plant, coupling):
    plant, _ = drake_plant
    assert plant.num_constraints() == 4  # coupler constraints from the mimic tags
    context = plant.CreateDefaultContext()
    index = _drake_positions(plant, coupling)
    G = coupling.matrix
    for theta in inside_stops(200, seed=5, config_dir=case.config_dir):
        q = np.zeros(plant.num_positions())
        q[index] = coupling.configuration(case.full(theta))
        plant.SetPositions(context, q)
        mass = plant.CalcMassMatrix(context)[np.ix_(index, index)]
        gravity = -plant.CalcGravityGeneralizedForces(context)[index]
        assert relative_error((G.T @ mass @ G)[:3, :3], case.mass(theta)) < 1e-9
        assert relative_error((G.T @ gravity)[:3], case.gravity(theta)) < 1e-9


def test_drake_sap_free_swing_follows_the_closed_form(case, drake_plant, coupling):
    """A discrete SAP plant at 1e-4 s, 0.15 s from rest at THETA0, within 1e-3 rad.

    Drake applies the URDF's joint damping (actuation.yaml's viscous friction); it has no
    dry friction for URDF joints."""
    plant, diagram = drake_plant
    context = diagram.CreateDefaultContext()
    plant_context = plant.GetMyMutableContextFromRoot(context)
    index = _drake_positions(plant, coupling)
    q = np.zeros(plant.num_positions())
    q[index] = coupling.configuration(case.full(THETA0))
    plant.SetPositions(plant_context, q)
    if case.config.gimbal is not None:  # held where phantom_pin holds it (Drake locks joints in SAP)
        for joint in GIMBAL_JOINTS:
            plant.GetJointByName(joint).Lock(plant_context)
    plant.get_actuation_input_port().FixValue(plant_context, np.zeros(plant.num_actuators()))
    drake.Simulator(diagram, context).AdvanceTo(0.15)
    theta = plant.GetPositions(plant_context)[index][:3]
    viscous = yaml.safe_load((case.config_dir / "actuation.yaml").read_text())["friction"]["viscous"]
    reference = rk4_closed_form(THETA0, 0.15, 1e-3 if len(case.locked) else 1e-4, case, damping=viscous)
    assert np.abs(theta - reference).max() < 1e-3
    assert np.abs(theta - THETA0).max() > 0.3  # it did swing


#: The one line of docs/tools.md that silences Drake's two known warnings on our URDFs (and no other).
SILENCE_DRAKE = ('logging.getLogger("drake").addFilter(lambda record: not any(known in record.getMessage() '
                 'for known in ("joint friction", "mechanical reductions")))')


def test_drake_warns_only_what_it_ignores_and_the_docs_line_silences_it(case):
    """Drake ignores the URDF's Coulomb friction (one warning per actuated joint) and a
    mechanicalReduction other than 1 (one per transmission; it uses drake:gear_ratio); the
    line of docs/tools.md ("In other tools") drops exactly those."""
    import logging

    readme = (Path(__file__).resolve().parents[2] / "docs" / "tools.md").read_text()
    assert SILENCE_DRAKE in readme

    class Records(logging.Handler):
        def __init__(self):
            super().__init__()
            self.messages = []

        def emit(self, record):
            self.messages.append(record.getMessage())

    def load():
        records = Records()
        logger.addHandler(records)
        try:
            builder = drake.DiagramBuilder()
            plant, _ = drake.AddMultibodyPlantSceneGraph(builder, time_step=1e-4)
            drake.Parser(plant).AddModels(str(case.urdf))
        finally:
            logger.removeHandler(records)
        return records.messages

    logger = logging.getLogger("drake")
    filters = list(logger.filters)
    messages = load()
    reductions = 0 if case.config.actuation.motor is None else 3
    assert sum("joint friction" in m for m in messages) == 3
    assert sum("mechanical reductions" in m for m in messages) == reductions
    assert len(messages) == 3 + reductions
    try:
        exec(SILENCE_DRAKE, {"logging": logging})
        assert load() == []
    finally:
        logger.filters[:] = filters


def test_the_docs_drake_snippet_fixes_the_base_and_gives_the_closed_forms_gravity():
    """The Drake block of docs/tools.md, run as written, on the default model: the base welded to the
    world (7 revolute positions, no floating body's 7 more), the 4 couplers, and the gravity of
    the closed form at seeded postures inside the stops (before, the README never fixed the
    base: the arm fell as a free body)."""
    import re

    readme = (Path(__file__).resolve().parents[2] / "docs" / "tools.md").read_text()
    block = next(b for b in re.findall(r"```python\n(.*?)```", readme, re.DOTALL) if "WeldFrames" in b)
    scope: dict = {}
    exec(block, scope)
    plant = scope["plant"]
    assert plant.num_positions() == 7 and plant.num_constraints() == 4
    model = config.MODELS["premium_1_5"]
    coupling = Coupling(model.urdf.read_text())
    index = _drake_positions(plant, coupling)
    context = plant.CreateDefaultContext()
    for theta in inside_stops(20, seed=8):
        q = np.zeros(plant.num_positions())
        q[index] = coupling.configuration(theta)
        plant.SetPositions(context, q)
        gravity = -plant.CalcGravityGeneralizedForces(context)[index]
        assert relative_error(coupling.matrix.T @ gravity, closed_form.gravity(theta, config.read().report)) < 1e-9
