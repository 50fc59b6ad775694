"""The ROS 2 package: what CMakeLists.txt installs exists, and the launch file's files and
packages are there and declared (read as text and Python syntax: no ROS needed here)."""

import ast
import re
import xml.etree.ElementTree as ET

from phantom_pin.paths import DESCRIPTION_DIR


def test_every_installed_folder_exists_and_holds_files():
    cmake = (DESCRIPTION_DIR / "CMakeLists.txt").read_text()
    package = ET.parse(DESCRIPTION_DIR / "package.xml").getroot()
    assert re.search(r"project\((\w+)", cmake).group(1) == package.findtext("name")
    (folders,) = re.findall(r"install\(DIRECTORY\s+([^)]*?)\s+DESTINATION", cmake, re.S)
    folders = folders.split()
    assert set(folders) >= {"urdf", "srdf", "mjcf", "config", "launch"}
    for folder in folders:
        assert any((DESCRIPTION_DIR / folder).iterdir()), folder
    assert package.findtext("buildtool_depend") == "ament_cmake"
    assert package.find("export/build_type").text == "ament_cmake"


def test_launch_file_reads_installed_files_and_declares_its_packages():
    launch = DESCRIPTION_DIR / "launch" / "display.launch.py"
    tree = ast.parse(launch.read_text())
    nodes = [call for call in ast.walk(tree)
             if isinstance(call, ast.Call) and getattr(call.func, "id", None) == "Node"]
    packages = {kw.value.value for call in nodes for kw in call.keywords if kw.arg == "package"}
    assert packages == {"robot_state_publisher", "joint_state_publisher_gui", "rviz2"}
    imported = {node.module.split(".")[0] for node in ast.walk(tree) if isinstance(node, ast.ImportFrom)}
    declared = {e.text for e in ET.parse(DESCRIPTION_DIR / "package.xml").getroot().findall("exec_depend")}
    assert packages | {"launch", "launch_ros"} <= declared
    assert {"launch", "launch_ros"} <= imported
    # the file it reads, relative to the package's share folder
    strings = [n.value for n in ast.walk(tree) if isinstance(n, ast.Constant) and isinstance(n.value, str)]
    assert {"urdf", "phantom_1_5.urdf"} <= set(strings)
    assert (DESCRIPTION_DIR / "urdf" / "phantom_1_5.urdf").is_file()
