"""load() against the SRDF and YAML read independently, the closed form and yourdfpy."""

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
import yaml
import yourdfpy

from helpers import CONFIG_DIR, REPORT, SRDF_PATH, URDF_PATH, relative_error
from phantom_pin.dynamics.loader import PhantomLoader, load, load_files
from phantom_pin.exceptions import InvalidInputError, ParameterFileError
from phantom_pin.report import closed_form


@pytest.fixture(scope="module")
def robot() -> pin.RobotWrapper:
    return load()


def _srdf_postures() -> dict[str, np.ndarray]:
    root = ET.parse(SRDF_PATH).getroot()
    return {state.get("name"): np.array([float(j.get("value")) for j in state.iter("joint")])
            for state in root.iter("group_state")}


def test_model_is_the_mimic_model_with_report_joint_names(robot):
    assert (robot.model.nq, robot.model.nv) == (3, 3)
    assert list(robot.model.names)[1:4] == ["joint1", "joint2", "joint3"]


def test_postures_and_q0_are_the_srdf_group_states(robot):
    postures = _srdf_postures()
    assert {"zero", "resting"} <= postures.keys()
    assert sorted(e.key() for e in robot.model.referenceConfigurations) == sorted(postures)
    for name, q in postures.items():
        np.testing.assert_array_equal(robot.model.referenceConfigurations[name], q)
    np.testing.assert_array_equal(robot.q0, postures[PhantomLoader.ref_posture])
    assert PhantomLoader.ref_posture == "resting"


def test_armature_is_rotor_inertia_times_ratio_squared_from_the_yaml(robot):
    actuation = yaml.safe_load((CONFIG_DIR / "actuation.yaml").read_text())
    ratios = [actuation["transmission_ratio"][j] for j in ("joint1", "joint2", "joint3")]
    expected = [actuation["motor"]["rotor_inertia"] * r**2 for r in ratios]
    np.testing.assert_allclose(robot.model.armature, expected, rtol=1e-12)


def test_dynamics_of_the_loaded_model_are_the_closed_form(robot, states):
    theta, dtheta, ddtheta = (s[:200] for s in states)
    mass = np.array([robot.mass(q) for q in theta])
    mass = np.triu(mass) + np.transpose(np.triu(mass, 1), (0, 2, 1))
    tau = np.array([pin.rnea(robot.model, robot.data, *x) for x in zip(theta, dtheta, ddtheta)])
    assert relative_error(mass, closed_form.mass_matrix(theta, REPORT)) < 1e-9
    assert relative_error(tau, closed_form.inverse_dynamics(theta, dtheta, ddtheta, REPORT)) < 1e-9


def test_visual_placements_match_yourdfpy(robot, states):
    """Every <visual> of the URDF, placed by Pinocchio and by yourdfpy, within 1e-9 m."""
    urdf_root = ET.parse(URDF_PATH).getroot()
    visuals = {link.get("name"): link.findall("visual") for link in urdf_root.iter("link")}
    assert robot.visual_model.ngeoms == sum(len(v) for v in visuals.values())
    urdf = yourdfpy.URDF.load(str(URDF_PATH))
    worst = 0.0
    for q in states[0][:50]:
        robot.framesForwardKinematics(q)
        pin.updateGeometryPlacements(robot.model, robot.data, robot.visual_model, robot.visual_data)
        urdf.update_cfg(q)
        for k, geometry in enumerate(robot.visual_model.geometryObjects):
            link, index = geometry.name.rsplit("_", 1)
            origin = visuals[link][int(index)].find("origin")
            xyz = [float(v) for v in origin.get("xyz", "0 0 0").split()] if origin is not None else [0, 0, 0]
            rpy = [float(v) for v in origin.get("rpy", "0 0 0").split()] if origin is not None else [0, 0, 0]
            local = pin.SE3(pin.rpy.rpyToMatrix(*rpy), np.array(xyz)).homogeneous
            expected = urdf.get_transform(link) @ local
            worst = max(worst, np.abs(robot.visual_data.oMg[k].homogeneous - expected).max())
    assert worst < 1e-9


def test_collision_pairs_skip_the_srdf_disabled_links_and_postures_are_free(robot):
    disabled = {frozenset((d.get("link1"), d.get("link2")))
                for d in ET.parse(SRDF_PATH).getroot().iter("disable_collisions")}
    geometries = robot.collision_model.geometryObjects
    links = [robot.model.frames[g.parentFrame].name for g in geometries]
    pairs = {frozenset((links[p.first], links[p.second])) for p in robot.collision_model.collisionPairs}
    assert pairs and not pairs & disabled
    for name, q in _srdf_postures().items():
        assert not pin.computeCollisions(robot.model, robot.data, robot.collision_model,
                                         robot.collision_data, q, True), name


def test_bad_loader_attributes_raise_named_errors():
    class NoFile(PhantomLoader):
        srdf_path = Path("/nonexistent/phantom.srdf")

    class NoPosture(PhantomLoader):
        ref_posture = "standing"

    with pytest.raises(ParameterFileError, match="srdf_path"):
        load_files(NoFile)
    with pytest.raises(InvalidInputError, match="ref_posture: 'standing'"):
        load_files(NoPosture)


@pytest.mark.parametrize("attribute, text, message", [
    ("urdf_path", "<robot", "urdf_path: .*not well-formed XML"),
    ("urdf_path", '<robot name="r"><link name="a"/><joint name="j" type="revolute"><parent link="a"/>'
                  '<child link="b"/></joint></robot>', "urdf_path: Pinocchio cannot load"),
    ("urdf_path", b"\xff\xfe\x00binary", "urdf_path: .* is not a text file"),
    ("srdf_path", "garbage", "srdf_path: Pinocchio cannot read"),
])
def test_malformed_urdf_or_srdf_raise_a_named_parameter_file_error(tmp_path, attribute, text, message):
    path = tmp_path / ("bad.urdf" if attribute == "urdf_path" else "bad.srdf")
    path.write_bytes(text if isinstance(text, bytes) else text.encode())
    loader = type("Bad", (PhantomLoader,), {attribute: path})
    with pytest.raises(ParameterFileError, match=message) as error:
        load_files(loader)
    assert "\n" not in str(error.value)


def test_a_folder_goes_through_describe(tmp_path):
    """load() takes a Description (None: the default model); a folder given directly is refused
    naming the way (load(describe(folder))), which gives the model of the same files: its gravity
    at a posture is the default model's (the folder is its copy), to 1e-12."""
    import shutil

    import numpy as np
    import pinocchio as pin

    from phantom_pin import InvalidInputError, describe, load
    from phantom_pin.config import MODELS

    folder = tmp_path / "mine"
    shutil.copytree(MODELS["premium_1_5"].config, folder)
    for bad in (folder, str(folder)):
        with pytest.raises(InvalidInputError, match=r"load\(describe\(folder\)\)") as error:
            load(bad)
        assert error.value.argument == "description"
    mine, shipped = load(describe(folder)), load()
    q = np.array([0.1, 0.4, 0.9])
    np.testing.assert_allclose(pin.computeGeneralizedGravity(mine.model, mine.data, q),
                               pin.computeGeneralizedGravity(shipped.model, shipped.data, q), rtol=0, atol=1e-12)


def test_load_refuses_what_is_not_a_description_naming_the_call():
    """A model name, a PhantomLoader class, a Phantom or anything else but a Description given
    to load() is refused with InvalidInputError naming ``description`` and the call that loads
    it; load_files() refuses anything but a PhantomLoader class, naming ``loader``."""
    from phantom_pin import InvalidInputError, Phantom, describe, load

    for bad, call in (("touch", "load(describe('touch'))"), (PhantomLoader, "load_files(loader)"),
                      (Phantom(), "load(phantom.description)"), (3, "load_files(loader)")):
        with pytest.raises(InvalidInputError) as error:
            load(bad)
        assert error.value.argument == "description" and call in error.value.detail, (bad, error.value.detail)
    for bad, call in ((describe("touch"), "load(description)"), ("touch", "load(describe(name or folder))"),
                      (PhantomLoader(), ""), (None, "")):
        with pytest.raises(InvalidInputError) as error:
            load_files(bad)
        assert error.value.argument == "loader" and call in error.value.detail, (bad, error.value.detail)


def test_load_and_load_files_of_the_same_files_are_the_same_robot():
    """load() (the default model's committed texts, with its Config's gravity) and load_files()
    (PhantomLoader: the same files read from disk, Pinocchio's gravity) give the same model:
    the same joints, postures, armature and gravity torques (the Config's g is Pinocchio's 9.81)."""
    import numpy as np
    import pinocchio as pin

    described, files = load(), load_files()
    assert list(described.model.names) == list(files.model.names)
    np.testing.assert_array_equal(described.q0, files.q0)
    np.testing.assert_array_equal(described.model.armature, files.model.armature)
    q = np.array([0.1, 0.4, 0.9])
    np.testing.assert_array_equal(pin.computeGeneralizedGravity(described.model, described.data, q),
                                  pin.computeGeneralizedGravity(files.model, files.data, q))
