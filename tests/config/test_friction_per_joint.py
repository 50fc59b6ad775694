"""Joint friction per joint: actuation.yaml's friction.viscous and friction.coulomb as one number
or a mapping {joint1, joint2, joint3}, the overrides of one joint, and every consumer (the URDF
read back by yourdfpy, the MJCF by MuJoCo, Drake's joint damping, the Device, the simulator's
plant, the identification's overlay, the command line) against the numbers written here.

The numbers differ per joint by factors 1.4-3, so that a swap of two joints anywhere fails."""

import dataclasses
import io
import logging
import math
import shutil

import mujoco
import numpy as np
import pydrake.all as drake
import pytest
import yourdfpy

from helpers import CONFIG_DIR
from phantom_pin import Device, Phantom, closed_form, config, simulate
from phantom_pin.cli import main
from phantom_pin.config.files import apply_overrides, read_documents
from phantom_pin.config.types import JOINTS, Friction
from phantom_pin.description.build import describe, driver_urdf
from phantom_pin.device.plant import Plant
from phantom_pin.exceptions import InvalidInputError, ParameterFileError
from phantom_pin.identification import Identification, overlay
from phantom_pin.identification.data import io as logs
from phantom_pin.identification.fitting import estimation
from phantom_pin.identification.structure import constants
from phantom_pin.identification.structure.structures import General, Report

#: Per joint, joint1..joint3: viscous (N m s/rad) and Coulomb (N m), written in the YAML below.
VISCOUS = (4.0e-4, 7.0e-4, 1.2e-3)
COULOMB = (8.0e-3, 1.5e-2, 5.0e-3)
MAPPING = ("friction:\n"
           f"  viscous: {{joint1: {VISCOUS[0]!r}, joint2: {VISCOUS[1]!r}, joint3: {VISCOUS[2]!r}}}\n"
           f"  coulomb: {{joint1: {COULOMB[0]!r}, joint2: {COULOMB[1]!r}, joint3: {COULOMB[2]!r}}}\n")
#: The same numbers as overrides of the shipped (one-number) file.
OVERRIDES = {f"actuation.friction.{kind}.{joint}": value for kind, values in (("viscous", VISCOUS),
                                                                              ("coulomb", COULOMB))
             for joint, value in zip(JOINTS, values, strict=True)}


def with_friction(folder, block: str) -> None:
    """Replace the friction block of folder/actuation.yaml (its four comment lines and two
    numbers) by ``block``."""
    path = folder / "actuation.yaml"
    lines = path.read_text().splitlines(keepends=True)
    start = next(i for i, line in enumerate(lines) if line.startswith("friction:"))
    end = next(i for i in range(start + 1, len(lines)) if not lines[i].startswith(" "))
    path.write_text("".join(lines[:start]) + block + "".join(lines[end:]))


@pytest.fixture()
def folder(tmp_path):
    """A copy of the default model's configuration folder with per-joint friction (a mapping)."""
    copy = tmp_path / "config"
    shutil.copytree(CONFIG_DIR, copy)
    with_friction(copy, MAPPING)
    return copy


@pytest.fixture(scope="module")
def overridden():
    return describe(overrides=OVERRIDES)


def test_a_mapping_and_the_overrides_give_each_joint_its_law(folder, overridden):
    """The YAML's mapping and the overrides of one joint each (of a file holding one number)
    give the same Friction, equal to the numbers written (exactly: they are read, not computed)."""
    expected = Friction(VISCOUS, COULOMB)
    assert config.read(folder).actuation.friction == expected
    assert overridden.config.actuation.friction == expected
    assert config.read(overrides={"friction.viscous.joint2": 7e-4}).actuation.friction == Friction(
        (5e-4, 7e-4, 5e-4), (0.01, 0.01, 0.01))          # unqualified key; the others keep the file's number


def _urdf_dynamics(text: str, joints=JOINTS) -> list[tuple[float, float]]:
    robot = yourdfpy.URDF.load(io.StringIO(text), build_scene_graph=False, load_meshes=False)
    return [(float(robot.joint_map[j].dynamics.damping), float(robot.joint_map[j].dynamics.friction))
            for j in joints]   # yourdfpy 0.0.60 keeps the attributes' text


def test_the_urdf_gives_each_joint_its_damping_and_friction(folder, overridden):
    """yourdfpy reads back each actuated joint's <dynamics damping friction> = the YAML's numbers
    (exactly: xacro prints them with str), in the report's and the drivers' conventions; the
    passive mimic joints have none."""
    expected = list(zip(VISCOUS, COULOMB, strict=True))
    assert _urdf_dynamics(describe(folder).urdf) == expected
    assert _urdf_dynamics(overridden.urdf) == expected
    touch = describe("touch", overrides=OVERRIDES)
    assert _urdf_dynamics(driver_urdf("touch", overrides=OVERRIDES), ("waist", "shoulder", "elbow")) == expected
    assert _urdf_dynamics(touch.urdf) == expected
    robot = yourdfpy.URDF.load(io.StringIO(overridden.urdf), build_scene_graph=False, load_meshes=False)
    assert [j.name for j in robot.robot.joints if j.dynamics is not None] == list(JOINTS)


def test_plain_xacro_reads_a_mapping_as_well_as_a_number(folder):
    """The macro takes actuation.yaml as a ROS user's xacro reads it (no phantom_pin): a mapping
    gives each joint its own numbers, as describe() does."""
    import xacro

    top = config.MODELS["premium_1_5"].urdf_xacro
    files = {f"{kind}_file": str(folder / f"{kind}.yaml")
             for kind in ("kinematics", "links", "actuation", "joint_limits", "visual_parameters")}
    plain = xacro.process_file(str(top), mappings=files).documentElement.toprettyxml(indent="  ")
    assert _urdf_dynamics(plain) == list(zip(VISCOUS, COULOMB, strict=True))


def test_the_mjcf_gives_each_joint_its_damping_and_frictionloss(overridden):
    """MuJoCo's dof_damping and dof_frictionloss of each actuated joint = the YAML's numbers."""
    model = mujoco.MjModel.from_xml_string(overridden.mjcf)
    dofs = [model.jnt_dofadr[model.joint(j).id] for j in JOINTS]
    assert model.dof_damping[dofs].tolist() == list(VISCOUS)
    assert model.dof_frictionloss[dofs].tolist() == list(COULOMB)


def test_drake_gives_each_joint_its_damping(overridden):
    """Drake's joint damping (the URDF's <dynamics damping>) of each actuated joint."""
    plant = drake.MultibodyPlant(0.0)
    logger = logging.getLogger("drake")
    quiet = logger.disabled
    logger.disabled = True       # its known warnings: Coulomb friction and mechanicalReduction ignored
    try:
        drake.Parser(plant).AddModelsFromString(overridden.urdf, "urdf")
    finally:
        logger.disabled = quiet
    assert [plant.GetJointByName(j).default_damping() for j in JOINTS] == list(VISCOUS)


def test_the_friction_torque_is_each_joints_law():
    """Friction.torque and Device.friction against the law written joint by joint in Python
    floats, single (3,) and batched (N, 3), to 1e-15 relative; another shape is refused
    naming dtheta."""
    law = Friction(VISCOUS, COULOMB)
    rates = np.random.default_rng(5).normal(0, 2, (50, 3))
    rates[0] = (0.0, -1e-9, 3.0)
    expected = [[VISCOUS[j] * v + math.copysign(COULOMB[j], v) * (v != 0) for j, v in enumerate(row)]
                for row in rates.tolist()]
    np.testing.assert_allclose(law.torque(rates), expected, rtol=1e-15, atol=0)
    np.testing.assert_allclose(law.torque(rates[3]), expected[3], rtol=1e-15, atol=0)
    device = Device(Phantom(describe(overrides=OVERRIDES)))
    np.testing.assert_allclose(device.friction(rates), expected, rtol=1e-15, atol=0)
    assert [law.joint(j) for j in range(3)] == list(zip(VISCOUS, COULOMB, strict=True))
    assert not law.uniform and Friction((1.0,) * 3, (2.0,) * 3).uniform
    with pytest.raises(InvalidInputError, match="dtheta"):
        law.torque(np.zeros(2))


def test_the_plant_slides_and_sticks_each_joint_by_its_own_law(overridden):
    """The simulator's plant: a sliding state's acceleration is Phantom.forward_dynamics under
    tau - each joint's law (to 1e-12 relative); at rest under gravity compensation plus 0.01 N m
    on joint 1 (which carries no gravity), joint 1 breaks away with its Coulomb torque 0.008 N m
    and sticks with the shipped 0.01 N m that holds exactly that much at most (and with 0.015)."""
    device = Device(Phantom(overridden))
    plant = Plant(device, friction=True, hard_stops=False, saturation=False, contact_step=1e-3)
    rng = np.random.default_rng(2)
    for _ in range(10):
        q, v, tau = rng.uniform(-0.5, 0.5, 3) + [0, 0.4, 0.6], rng.normal(0, 1, 3), rng.normal(0, 0.05, 3)
        law = np.array(VISCOUS) * v + np.array(COULOMB) * np.sign(v)
        expected = device.phantom.forward_dynamics(q, v, tau - law)
        np.testing.assert_allclose(plant.acceleration(q.tolist(), v.tolist(), tau.tolist()), expected,
                                   rtol=1e-12, atol=1e-12 * np.abs(expected).max())
    q = [0.2, 0.5, 0.7]
    push = device.phantom.gravity(np.array(q)) + [0.01, 0.0, 0.0]
    assert plant.acceleration(q, [0.0] * 3, push.tolist())[0] > 0             # 0.01 > 0.008: it slides
    stuck = Plant(Device(Phantom(describe(overrides={**OVERRIDES, "actuation.friction.coulomb.joint1": 0.0101}))),
                  friction=True, hard_stops=False, saturation=False, contact_step=1e-3)
    assert list(stuck.acceleration(q, [0.0] * 3, push.tolist())) == [0.0, 0.0, 0.0]


def test_simulate_dissipates_each_joints_viscous_power():
    """Unpowered, without Coulomb friction or stops: the energy lost over 0.5 s equals the
    integral of sum_j b_j dtheta_j^2 with each joint's own b_j (trapezoid at 10 kHz, within
    1e-4 of it); with the joints' coefficients rotated it is off by more than 10 %."""
    overrides = {**{k: v for k, v in OVERRIDES.items() if "viscous" in k},
                 **{f"actuation.friction.coulomb.{j}": 0.0 for j in JOINTS}}
    device = Device(Phantom(describe(overrides=overrides)))
    result = simulate([0.0, 0.3, 0.5], 0.5, dtheta0=[6.0, -3.0, 4.0], rate=1e4, hard_stops=False,
                      saturation=False, device=device)
    theta, dtheta = result.theta, result.dtheta
    kinetic = 0.5 * np.einsum("ni,nij,nj->n", dtheta, device.phantom.mass_matrix(theta), dtheta)
    energy = kinetic + device.phantom.potential_energy(theta)
    lost = energy[0] - energy[-1]

    def dissipated(b):
        power = (np.asarray(b) * dtheta**2).sum(axis=1)
        return float(np.sum(0.5 * (power[1:] + power[:-1]) * np.diff(result.t)))

    assert lost == pytest.approx(dissipated(VISCOUS), rel=1e-4)
    assert abs(dissipated(VISCOUS[1:] + VISCOUS[:1]) / lost - 1) > 0.1


def test_overrides_of_per_joint_keys():
    """apply_overrides: one joint of a number expands it to the three joints; the whole key on
    a mapping sets every joint (a number again); a joint on a mapping sets that joint only."""
    documents = read_documents(CONFIG_DIR)
    one = apply_overrides(documents, {"actuation.friction.viscous.joint2": 7e-4})
    assert one["actuation_file"]["friction"]["viscous"] == {"joint1": 5e-4, "joint2": 7e-4, "joint3": 5e-4}
    assert documents["actuation_file"]["friction"]["viscous"] == 5e-4                  # a copy
    whole = apply_overrides(one, {"friction.viscous": 9e-4})
    assert whole["actuation_file"]["friction"]["viscous"] == 9e-4
    again = apply_overrides(one, {"actuation.friction.viscous.joint3": 1e-3})
    assert again["actuation_file"]["friction"]["viscous"] == {"joint1": 5e-4, "joint2": 7e-4, "joint3": 1e-3}
    assert config.read(overrides={**OVERRIDES, "actuation.friction.coulomb": 0.02}).actuation.friction == Friction(
        VISCOUS, (0.02,) * 3)


@pytest.mark.parametrize("overrides, message", [
    ({"actuation.friction.viscous.joint4": 1e-3}, "actuation.friction.viscous.joint4: friction.viscous is per joint"),
    ({"actuation.friction.viscous.joint2": "a"}, "actuation.friction.viscous.joint2: expected a finite number"),
    ({"actuation.friction.viscous.joint2": math.inf}, "actuation.friction.viscous.joint2: expected a finite number"),
    ({"actuation.friction.coulomb.joint3": -0.01}, "friction.coulomb.joint3 must not be negative"),
    ({"actuation.motor.rotor_inertia.joint2": 1e-6}, "actuation.motor.rotor_inertia.joint2: not a number"),
])
def test_bad_per_joint_overrides_are_refused_naming_the_key(overrides, message):
    with pytest.raises(ParameterFileError, match=message.replace(".", r"\.")):
        describe(overrides=overrides)


@pytest.mark.parametrize("block, message", [
    ("friction:\n  viscous: {joint1: 1.0e-3, joint2: 1.0e-3}\n  coulomb: 0.01\n",
     "missing key friction.viscous.joint3"),
    ("friction:\n  viscous: {joint1: 1.0e-3, joint2: -1.0e-3, joint3: 1.0e-3}\n  coulomb: 0.01\n",
     "friction.viscous.joint2 must not be negative"),
    ("friction:\n  viscous: 5.0e-4\n  coulomb: {joint1: 0.01, joint2: high, joint3: 0.01}\n",
     "friction.coulomb.joint2 must be a finite number, got 'high'"),
    ("friction:\n  viscous: 5.0e-4\n  coulomb: {joint1: 0.01, joint2: .nan, joint3: 0.01}\n",
     "friction.coulomb.joint2 must be a finite number"),
    ("friction:\n  viscous: {joint1: 1.0e-3, joint2: 1.0e-3, joint3: 1.0e-3, joint4: 1.0e-3}\n  coulomb: 0.01\n",
     "friction.viscous.joint4 is not a joint"),
    ("friction:\n  viscous: low\n  coulomb: 0.01\n", "friction.viscous must be a finite number .* or a mapping"),
    ("friction:\n  viscous: [1.0e-3, 1.0e-3, 1.0e-3]\n  coulomb: 0.01\n", "friction.viscous must be a finite number"),
])
def test_bad_per_joint_files_are_refused_naming_the_key(folder, block, message):
    with_friction(folder, block)
    with pytest.raises(ParameterFileError, match=f"actuation.yaml: {message}"):
        config.read(folder)


def _exact_log(law: Friction) -> logs.Log:
    """10 s at 1 kHz of one sine per joint (exact rates), the report's inverse dynamics plus ``law``."""
    t = np.arange(10001) / 1000.0
    w, amplitude, offset = np.array([1.3, 1.9, 2.7]), np.array([0.6, 0.3, 0.35]), np.array([0.0, 0.3, 0.45])
    theta = offset + amplitude * np.sin(np.outer(t, w))
    dtheta = amplitude * w * np.cos(np.outer(t, w))
    ddtheta = -amplitude * w**2 * np.sin(np.outer(t, w))
    model = config.read()
    return logs.Log(t, theta, closed_form.inverse_dynamics(theta, dtheta, ddtheta, model.report) + law.torque(dtheta))


@pytest.fixture(scope="module")
def fit():
    """The report structure's fit of an exact log of per-joint friction."""
    return estimation.estimate(_exact_log(Friction(VISCOUS, COULOMB)), Phantom(), structure="report", timing="sampled")


def test_the_overlay_writes_each_joints_friction_and_reads_back(fit, tmp_path):
    """estimate() on an exact log of per-joint friction, then overlay(): six friction keys (the
    fit's physical values fit.x[-6:], viscous1..3 then coulomb1..3; a given friction key
    dropped), the comments listing each joint's estimate +- sigma; describe(overrides=keys)
    gives exactly that Friction, also through the written file; the values are the log's own
    within 2 %."""
    keys, notes = overlay(fit, {"actuation.friction.viscous": 1.0}, config.read())
    written = {k: v for k, v in keys.items() if "friction" in k}
    assert list(written) == [f"actuation.friction.{kind}.{j}" for kind in ("viscous", "coulomb") for j in JOINTS]
    assert list(written.values()) == fit.x[-6:].tolist()
    expected = Friction(tuple(fit.x[-6:-3].tolist()), tuple(fit.x[-3:].tolist()))
    assert describe(overrides=keys).config.actuation.friction == expected
    np.testing.assert_allclose(fit.x[-6:], VISCOUS + COULOMB, rtol=0.02)
    assert [n.split(":")[0] for n in notes] == ["friction.viscous estimated per joint", "friction.coulomb estimated "
                                                "per joint"]
    assert all(n.count("+-") == 3 and "joint3" in n for n in notes)
    path = tmp_path / "id.yaml"
    Identification(fit, keys, notes, "exact", 1000.0, fit.samples, 20.0).write(path)
    assert describe(overrides=config.read_overrides(path)).config.actuation.friction == expected


def test_cli_set_gives_one_joint_its_damping(tmp_path, capsys):
    """phantom-pin urdf --set actuation.friction.viscous.joint2=1e-3: that joint's damping, the
    others the shipped 5e-4; info prints the per-joint law, and today's line when they agree."""
    path = tmp_path / "a.urdf"
    assert main(["urdf", "-o", str(path), "--set", "actuation.friction.viscous.joint2=1e-3"]) == 0
    assert _urdf_dynamics(path.read_text()) == [(5e-4, 0.01), (1e-3, 0.01), (5e-4, 0.01)]
    capsys.readouterr()
    assert main(["info", "--set", "actuation.friction.viscous.joint2=1e-3"]) == 0
    assert ("friction per joint: viscous [0.0005 0.001 0.0005] N m s/rad + coulomb [0.01 0.01 0.01] N m * "
            "sign(dtheta) in motion; at rest a joint sticks below its Coulomb torque") in capsys.readouterr().out
    assert main(["info"]) == 0
    assert ("friction: viscous 0.0005 N m s/rad + coulomb 0.01 N m * sign(dtheta) in motion; at rest a joint "
            "sticks below the Coulomb torque") in capsys.readouterr().out


def test_joints_that_differ_beyond_their_uncertainty_are_each_written(fit):
    """Before, overlays.friction_overlay pooled the joints into one inverse-variance mean and
    wrote nothing when one joint lay beyond max(3 sigma, 20 %) of it (joint 3 here: 30 % above
    and hundreds of sigmas): the model kept the configuration's value. Now each joint's value
    is written as it is, and the model built from the overlay has it (exactly)."""
    x = fit.x.copy()
    x[-6:] = [1.0e-3, 1.0e-3, 1.3e-3, 0.01, 0.01, 0.013]
    differing = dataclasses.replace(fit, x=x)
    keys, _ = overlay(differing)
    assert [keys[f"actuation.friction.{kind}.joint3"] for kind in ("viscous", "coulomb")] == [1.3e-3, 0.013]
    law = describe(overrides=keys).config.actuation.friction
    assert law == Friction((1.0e-3, 1.0e-3, 1.3e-3), (0.01, 0.01, 0.013))


def test_the_identification_starts_from_each_joints_law(overridden):
    """The prior of both structures and the report's beta (constants.nominal) carry the
    configuration's friction joint by joint, viscous1..3 then coulomb1..3."""
    phantom = Phantom(overridden)
    for structure in (General(phantom), Report(phantom)):
        assert structure.friction_prior.tolist() == list(VISCOUS + COULOMB)
    assert constants.nominal(overridden)[-6:].tolist() == list(VISCOUS + COULOMB)


@pytest.mark.parametrize("viscous", [0.001, (1e-3, 1e-3), (1e-3, 1e-3, -1e-3), ("a", 1e-3, 1e-3),
                                     (1e-3, 1e-3, float("nan")), (True, 1e-3, 1e-3), None])
def test_a_friction_built_in_code_is_checked_like_the_file(viscous):
    """Friction(viscous, coulomb) in code: three finite coefficients >= 0 each, as actuation.yaml's
    reader demands; anything else (the old single number too) raises InvalidInputError naming it."""
    with pytest.raises(InvalidInputError, match="viscous: expected three finite numbers >= 0"):
        Friction(viscous, (0.01, 0.01, 0.01))
    with pytest.raises(InvalidInputError, match="coulomb: expected three finite numbers >= 0"):
        Friction((0.0, 0.0, 0.0), viscous)
    assert Friction([1, 2, 3], np.array([4.0, 5.0, 6.0])) == Friction((1.0, 2.0, 3.0), (4.0, 5.0, 6.0))
