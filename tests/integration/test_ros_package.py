"""The ROS 2 package: what CMakeLists.txt installs exists; colcon (Debian's, with ament_cmake)
builds and installs it; the launch file declares its packages and shows every committed robot
(run against stand-ins of ROS 2's launch API, which Debian does not ship)."""

import ast
import importlib.util
import os
import re
import shutil
import subprocess
import sys
import types
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from phantom_pin._paths import DESCRIPTION_DIR
from phantom_pin.config import MODELS

#: Debian's python, which has ament_package (python3-ament-package, with ament-cmake).
SYSTEM_PYTHON = "/usr/bin/python3"


def test_every_installed_folder_exists_and_holds_files():
    cmake = (DESCRIPTION_DIR / "CMakeLists.txt").read_text()
    package = ET.parse(DESCRIPTION_DIR / "package.xml").getroot()
    assert re.search(r"project\((\w+)", cmake).group(1) == package.findtext("name")
    (folders,) = re.findall(r"install\(DIRECTORY\s+([^)]*?)\s+DESTINATION share", cmake, re.S)
    folders = folders.split()
    assert re.search(r"install\(DIRECTORY include/\s+DESTINATION include/\$\{PROJECT_NAME\}\)", cmake)
    assert set(folders) >= {"urdf", "srdf", "mjcf", "config", "launch"}
    for folder in folders:
        assert any((DESCRIPTION_DIR / folder).iterdir()), folder
    assert package.findtext("buildtool_depend") == "ament_cmake"
    assert package.find("export/build_type").text == "ament_cmake"


def test_launch_file_declares_its_packages():
    launch = DESCRIPTION_DIR / "launch" / "display.launch.py"
    tree = ast.parse(launch.read_text())
    nodes = [call for call in ast.walk(tree)
             if isinstance(call, ast.Call) and getattr(call.func, "id", None) == "Node"]
    packages = {kw.value.value for call in nodes for kw in call.keywords if kw.arg == "package"}
    assert packages == {"robot_state_publisher", "joint_state_publisher_gui", "rviz2"}
    imported = {node.module.split(".")[0] for node in ast.walk(tree) if isinstance(node, ast.ImportFrom)}
    declared = {e.text for e in ET.parse(DESCRIPTION_DIR / "package.xml").getroot().findall("exec_depend")}
    assert packages | {"launch", "launch_ros"} <= declared
    assert {"launch", "launch_ros", "ament_index_python"} <= imported


def _stub_modules(share: Path) -> dict[str, types.ModuleType]:
    """Minimal stand-ins for ROS 2's launch API (not installable here): each class records its
    arguments, LaunchConfiguration.perform reads the context's launch arguments."""
    def recorder(name):
        return type(name, (), {"__init__": lambda self, *args, **kwargs: self.__dict__.update(args=args, **kwargs)})

    class LaunchConfiguration:
        def __init__(self, name):
            self.name = name

        def perform(self, context):
            return context[self.name]

    modules = {name: types.ModuleType(name) for name in
               ("ament_index_python", "ament_index_python.packages", "launch", "launch.actions",
                "launch.substitutions", "launch_ros", "launch_ros.actions")}
    modules["ament_index_python.packages"].get_package_share_directory = \
        lambda package: str(share) if package == "phantom_description" else None
    modules["launch"].LaunchDescription = lambda entities: entities
    modules["launch.actions"].DeclareLaunchArgument = recorder("DeclareLaunchArgument")
    modules["launch.actions"].OpaqueFunction = recorder("OpaqueFunction")
    modules["launch.actions"].ExecuteProcess = recorder("ExecuteProcess")
    modules["launch.substitutions"].LaunchConfiguration = LaunchConfiguration
    modules["launch_ros.actions"].Node = recorder("Node")
    return modules


def test_launch_file_shows_each_committed_robot(monkeypatch):
    """generate_launch_description, run against the stand-ins with the source tree as the share
    folder: the default and every choice of ``robot`` hand robot_state_publisher that URDF."""
    for name, module in _stub_modules(DESCRIPTION_DIR).items():
        monkeypatch.setitem(sys.modules, name, module)
    spec = importlib.util.spec_from_file_location("display_launch", DESCRIPTION_DIR / "launch" / "display.launch.py")
    launch = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(launch)
    argument, convention, gui, node, opaque = launch.generate_launch_description()
    committed = sorted(p.stem for p in (DESCRIPTION_DIR / "urdf").glob("*.urdf") if not p.stem.endswith("_driver"))
    assert sorted(argument.choices) == committed == sorted(m.urdf.stem for m in MODELS.values())
    for robot in [argument.default_value, *argument.choices]:
        publisher, gui_node, rviz = opaque.function({"robot": robot, "convention": "report", "gui": "true",
                                                     "node": "false"})
        assert publisher.package == "robot_state_publisher" and gui_node.package == "joint_state_publisher_gui"
        assert publisher.parameters == [{"robot_description": (DESCRIPTION_DIR / "urdf" / f"{robot}.urdf").read_text()}]
    assert argument.default_value == "premium_1_5"
    # the Touch in the drivers' convention, its joint_states from a running driver (no GUI)
    assert convention.choices == ["report", "driver"] and gui.default_value == "true"
    publisher, rviz = opaque.function({"robot": "touch", "convention": "driver", "gui": "false",
                                       "node": "false"})
    assert publisher.parameters == [{"robot_description": (DESCRIPTION_DIR / "urdf" /
                                                           "touch_driver.urdf").read_text()}]
    assert rviz.package == "rviz2"
    with pytest.raises(RuntimeError, match="convention:=driver: no premium_1_5_driver.urdf"):
        opaque.function({"robot": "premium_1_5", "convention": "driver", "gui": "true", "node": "false"})
    # phantom_pin's node beside robot_state_publisher: the command line docs/ros2.md gives, which
    # parses (the model is the robot's)
    assert node.default_value == "false"
    publisher, ours, rviz = opaque.function({"robot": "touch", "convention": "driver", "gui": "false",
                                             "node": "true"})
    assert ours.cmd == ["phantom-pin", "--model", "touch", "ros2"]
    from phantom_pin.cli.app import parser
    assert parser().parse_args(ours.cmd[1:]).run.__name__ == "ros2"


@pytest.mark.colcon
def test_colcon_builds_and_installs_the_package_and_xacro_reproduces_the_urdfs(tmp_path):
    """Debian's colcon and ament_cmake (.ci/run installs them) build the package; the installed
    tree holds every installed folder's files unchanged, and plain xacro on each installed
    top-level xacro gives the committed URDF (comments aside: xacro's banner names its input).

    Built as from an activated virtual environment (VIRTUAL_ENV set, its python first on PATH,
    as `. .venv/bin/activate && pytest` runs it): CMake's FindPython would then take the venv's
    python, which lacks ament_package, so the build names /usr/bin/python3 (Debian's, which has
    it) for CMake and puts /usr/bin first on PATH."""
    colcon = shutil.which("colcon", path="/usr/bin")
    shutil.copytree(DESCRIPTION_DIR, tmp_path / "src" / "phantom_description")
    venv = Path(sys.prefix)
    environment = {**os.environ, "VIRTUAL_ENV": str(venv),
                   "PATH": f"/usr/bin:{venv / 'bin'}:{os.environ['PATH']}"}
    build = subprocess.run([colcon, "build", "--base-paths", "src", "--build-base", "build",
                            "--install-base", "install", "--cmake-args", f"-DPython3_EXECUTABLE={SYSTEM_PYTHON}"],
                           cwd=tmp_path, env=environment, capture_output=True, text=True)
    assert build.returncode == 0, build.stdout + build.stderr
    share = tmp_path / "install" / "phantom_description" / "share" / "phantom_description"
    for folder in ("config", "launch", "mjcf", "srdf", "urdf"):
        for source in (DESCRIPTION_DIR / folder).rglob("*"):
            if source.is_file():
                installed = share / source.relative_to(DESCRIPTION_DIR)
                assert installed.read_bytes() == source.read_bytes(), installed
    assert (share / "package.xml").is_file()
    headers = sorted((DESCRIPTION_DIR / "include").glob("*.h"))
    assert headers  # the C servo-loop headers, under include/phantom_description/
    for header in headers:
        installed = tmp_path / "install" / "phantom_description" / "include" / "phantom_description" / header.name
        assert installed.read_bytes() == header.read_bytes(), installed
    xacro = Path(sys.executable).parent / "xacro"
    for model in MODELS.values():
        top = share / "urdf" / model.urdf_xacro.name
        result = subprocess.run([str(xacro), str(top), *model.xacro_args], capture_output=True, text=True,
                                cwd=top.parent)
        assert result.returncode == 0, result.stderr
        assert ET.canonicalize(result.stdout, strip_text=True) == \
            ET.canonicalize(model.urdf.read_text(), strip_text=True), model.name
    # the Touch in the drivers' convention, from the installed top-level file
    top = share / "urdf" / MODELS["touch"].urdf_xacro.name
    result = subprocess.run([str(xacro), str(top), "model:=touch", "convention:=driver"], capture_output=True,
                            text=True, cwd=top.parent)
    assert result.returncode == 0, result.stderr
    assert ET.canonicalize(result.stdout, strip_text=True) == \
        ET.canonicalize((share / "urdf" / "touch_driver.urdf").read_text(), strip_text=True)
