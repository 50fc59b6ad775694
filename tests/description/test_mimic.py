"""description.mimic: the <mimic> tags of each committed URDF and of example-robot-data's PR2 and
Baxter against yourdfpy's reading of them (joint, primary, multiplier, offset: exact), the
defaults of a bare tag (multiplier 1, offset 0), and a tag naming no joint refused."""

from importlib.metadata import distribution
from pathlib import Path

import pytest
import yourdfpy

from phantom_pin import ParameterFileError, config
from phantom_pin.description.mimic import Mimic, read_mimic_tags


def _example(relative):
    files = distribution("example-robot-data").files
    package_xml = next(f for f in files if f.name == "package.xml" and "example-robot-data" in str(f))
    return Path(package_xml.locate()).parent / "robots" / relative


@pytest.mark.parametrize("path", [config.MODELS["premium_1_5"].urdf, config.MODELS["premium_1_5_cad"].urdf,
                                  config.MODELS["touch"].urdf, "pr2_description/urdf/pr2.urdf",
                                  "baxter_description/urdf/baxter.urdf"],
                         ids=["premium_1_5", "premium_1_5_cad", "touch", "pr2", "baxter"])
def test_the_tags_are_yourdfpys(path):
    path = path if isinstance(path, Path) else _example(path)
    robot = yourdfpy.URDF.load(str(path), build_scene_graph=False, load_meshes=False,
                               build_collision_scene_graph=False, load_collision_meshes=False).robot
    expected = {j.name: Mimic(j.name, j.mimic.joint, float(j.mimic.multiplier), float(j.mimic.offset))
                for j in robot.joints if j.mimic is not None}
    assert expected                                     # each of these has mimic joints
    assert read_mimic_tags(path.read_text(encoding="utf-8")) == expected


def test_a_bare_tag_has_the_defaults_and_a_tag_naming_no_joint_is_refused():
    urdf = """<robot name="r"><joint name="b" type="revolute"><mimic joint="a"/></joint>
    <joint name="c" type="revolute"><mimic joint="a" multiplier="-2.5" offset="0.25"/></joint>
    <joint name="a" type="revolute"/></robot>"""
    assert read_mimic_tags(urdf) == {"b": Mimic("b", "a", 1.0, 0.0), "c": Mimic("c", "a", -2.5, 0.25)}
    with pytest.raises(ParameterFileError, match="the mimic a joint .*mimic of None"):
        read_mimic_tags('<robot name="r"><joint name="b"><mimic multiplier="2"/></joint></robot>')
    with pytest.raises(ParameterFileError, match="^URDF: not well-formed XML"):
        read_mimic_tags("<robot")
