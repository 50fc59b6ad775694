"""Every model's committed URDF in Gazebo's URDF parser: Debian's libsdformat (sdformat 12, the
parser of Gazebo Fortress), through tests/sdformat_probe.cpp, against the URDF and the YAML read
here. .ci/run installs libsdformat-dev, g++ and pkg-config."""

import re
import shutil
import subprocess
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
import yaml

from phantom_pin.config import MODELS, models

pytestmark = pytest.mark.sdformat
PROBE = Path(__file__).parents[1] / "sdformat_probe.cpp"
#: sdformat's joint type enumeration (sdf::JointType): 6 is REVOLUTE.
REVOLUTE = 6


@pytest.fixture(scope="module")
def probe(tmp_path_factory) -> Path:
    """The probe, compiled once against the installed sdformat 12."""
    assert shutil.which("g++") and shutil.which("pkg-config"), "g++ and pkg-config are needed (.ci/run installs them)"
    flags = subprocess.run(["pkg-config", "--cflags", "--libs", "sdformat12"], capture_output=True, text=True)
    assert flags.returncode == 0, "Debian's libsdformat-dev (sdformat 12) is needed: .ci/run installs it"
    binary = tmp_path_factory.mktemp("sdformat") / "probe"
    build = subprocess.run(["g++", "-O0", "-o", str(binary), str(PROBE), *flags.stdout.split()],
                           capture_output=True, text=True)
    assert build.returncode == 0, build.stderr
    return binary


def parse(probe: Path, urdf: Path) -> dict:
    """The probe's report of ``urdf``: errors, links, joints, frames, number of mimic tags."""
    out = subprocess.run([str(probe), str(urdf)], capture_output=True, text=True, check=True).stdout
    report = {"errors": [], "links": {}, "joints": {}, "frames": {}, "mimic": None}
    for line in out.splitlines():
        kind, _, rest = line.partition(" ")
        if kind == "ERROR":
            report["errors"].append(rest)
        elif kind == "LINK":
            name, *numbers = rest.split()
            report["links"][name] = [float(v) for v in numbers]
        elif kind == "JOINT":
            name, kind_, parent, child, *numbers = rest.split()
            report["joints"][name] = (int(kind_), parent, child, [float(v) for v in numbers])
        elif kind == "FRAME":
            report["frames"][rest.split()[0]] = rest
        elif kind == "MIMIC":
            report["mimic"] = int(rest)
    return report


def test_the_installed_parser_is_sdformat_12():
    version = subprocess.run(["pkg-config", "--modversion", "sdformat12"], capture_output=True, text=True)
    assert version.stdout.startswith("12."), version.stdout


@pytest.mark.parametrize("name", models())
def test_every_link_survives_with_its_mass_inertia_and_centre_of_mass(probe, name):
    urdf = ET.parse(MODELS[name].urdf).getroot()
    report = parse(probe, MODELS[name].urdf)
    assert report["errors"] == []
    expected = {}
    for link in urdf.findall("link"):
        inertial = link.find("inertial")
        if inertial is None:
            continue
        i = inertial.find("inertia").attrib
        expected[link.get("name")] = [float(inertial.find("mass").get("value")),
                                      *(float(i[k]) for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")),
                                      *(float(v) for v in inertial.find("origin").get("xyz").split())]
        assert inertial.find("origin").get("rpy") == "0 0 0"
    gimbal = (MODELS[name].config / "gimbal.yaml").exists()  # yaw_link, pitch_link, stylus_link kept
    assert len(expected) == 8 + 3 * gimbal and set(report["links"]) == set(expected)
    for link, values in expected.items():
        np.testing.assert_allclose(report["links"][link], values, rtol=1e-15, atol=0, err_msg=link)


@pytest.mark.parametrize("name", models())
def test_the_housing_is_the_yamls_estimate_on_base_link(probe, name):
    housing = yaml.safe_load((MODELS[name].config / "physical_parameters.yaml").read_text())["housing"]
    i = housing["inertia"]
    values = parse(probe, MODELS[name].urdf)["links"]["base_link"]
    assert values == [housing["mass"], *(float(i[k]) for k in ("xx", "xy", "xz", "yy", "yz", "zz")),
                      *map(float, housing["com"])]


@pytest.mark.parametrize("name", models())
def test_every_joint_survives_with_its_axis_limits_and_dynamics(probe, name):
    urdf = ET.parse(MODELS[name].urdf).getroot()
    report = parse(probe, MODELS[name].urdf)
    revolute = [j for j in urdf.findall("joint") if j.get("type") == "revolute"]
    gimbal = (MODELS[name].config / "gimbal.yaml").exists()  # joint4..joint6
    assert len(revolute) == 7 + 3 * gimbal and set(report["joints"]) == {j.get("name") for j in revolute}
    for joint in revolute:
        kind, parent, child, numbers = report["joints"][joint.get("name")]
        assert (kind, parent, child) == (REVOLUTE, joint.find("parent").get("link"), joint.find("child").get("link"))
        limit, dynamics = joint.find("limit"), joint.find("dynamics")
        expected = [*(float(v) for v in joint.find("axis").get("xyz").split()),
                    *(float(limit.get(k)) for k in ("lower", "upper", "effort", "velocity")),
                    *((float(dynamics.get(k)) for k in ("damping", "friction"))
                      if dynamics is not None else (0.0, 0.0))]
        np.testing.assert_allclose(numbers, expected, rtol=1e-15, atol=0, err_msg=joint.get("name"))


@pytest.mark.parametrize("name", models())
def test_sdformat_12_drops_the_mimic_tags_and_the_massless_frames(probe, name):
    """What a Gazebo Fortress user loses (docs/tools.md's Gazebo section says what to do): the four
    <mimic> tags (SDFormat gained //joint/axis/mimic and its URDF parser reads them from Gazebo
    Harmonic on: gazebosim/sdformat#1333), so the parallelogram's pin joints are free; and the
    massless frame links (tip, report_s, report_dynamics, elbow), with their fixed joints."""
    text = MODELS[name].urdf.read_text()
    assert len(re.findall(r"<mimic ", text)) == 4
    report = parse(probe, MODELS[name].urdf)
    assert report["mimic"] == 0 and report["frames"] == {}
    assert not {"tip", "report_s", "report_dynamics", "elbow", "stylus", "stylus_tip"} & set(report["links"])


def test_without_the_housing_gazebo_drops_the_whole_arm(probe, tmp_path):
    """The failure base_link's inertial fixes: sdformat drops a root link without <inertial>,
    with every child."""
    root = ET.parse(MODELS["premium_1_5"].urdf).getroot()
    base = root.find("link[@name='base_link']")
    base.remove(base.find("inertial"))
    stripped = tmp_path / "stripped.urdf"
    ET.ElementTree(root).write(stripped)
    report = parse(probe, stripped)
    assert report["links"] == {} and any("at least one link" in e for e in report["errors"])


def test_a_world_link_around_the_macro_fixes_the_arm_to_gazebos_world(probe, tmp_path):
    """docs/tools.md's advice for a fixed base: a `world` link and a fixed joint to base_link in
    the user's own top-level file; sdformat makes it a joint fixed to the world (type 3)."""
    root = ET.parse(MODELS["touch"].urdf).getroot()
    root.insert(0, ET.fromstring('<joint name="world_joint" type="fixed"><parent link="world"/>'
                                 '<child link="base_link"/></joint>'))
    root.insert(0, ET.Element("link", name="world"))
    fixed = tmp_path / "fixed.urdf"
    ET.ElementTree(root).write(fixed)
    report = parse(probe, fixed)
    assert report["errors"] == [] and len(report["links"]) == 8 + 3  # the Touch's gimbal links too
    assert report["joints"]["world_joint"][:3] == (3, "world", "base_link")
