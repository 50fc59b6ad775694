"""Documentation that states facts: the README's quick start, the YAML's comments, and docs/cli.md's
Ctrl-C sentence and command table."""

import re
import xml.etree.ElementTree as ET
from pathlib import Path

import yaml

from phantom_pin.config import MODELS

CONFIG_DIR, URDF_PATH = MODELS["premium_1_5"].config, MODELS["premium_1_5"].urdf

ROOT = Path(__file__).resolve().parents[2]


def test_readme_quick_start_says_how_to_get_chromium_for_the_tests():
    quick_start = (ROOT / "README.md").read_text().split("## Quick start")[1].split("\n## ")[0]
    assert "sudo apt-get install chromium" in quick_start and ".ci/run" in quick_start


def test_motor_offsets_are_from_the_shoulder_in_the_urdf_and_in_the_yaml_comments():
    """The motor cylinders sit at the offsets from the link origins, which are the shoulder
    (joint2/joint3 have zero origins in turret_link, itself at the shoulder); the YAML's
    comments must say so."""
    text = (CONFIG_DIR / "visual_parameters.yaml").read_text()
    motor = yaml.safe_load(text)["motor"]
    root = ET.parse(URDF_PATH).getroot()
    joints = {j.find("child").get("link"): j for j in root.findall("joint")}
    for link, key, axis in (("upper_arm_link", "motor_e_offset_z", 0), ("crank_link", "motor_d_offset_y", 2)):
        assert joints[link].find("origin").get("xyz") == "0 0 0"
        assert joints["turret_link"].find("origin").get("xyz") == "0 0 0"
        origins = [[float(v) for v in visual.find("origin").get("xyz").split()]
                   for visual in root.find(f"link[@name='{link}']").iter("visual")]
        assert [motor[key] if a == axis else 0.0 for a in range(3)] in origins
        comment = re.search(rf"{key}:[^#]*#(.*)", text).group(1)
        assert "from the shoulder" in comment and "centre of mass" not in comment, comment


def test_simulation_doc_quotes_the_shipped_friction_and_stops():
    """docs/simulation.md argues from the Premium 1.5's numbers; they must be the YAML's: the
    friction levels, the stop model, and the LuGre bristle stiffness below which presliding
    (Fc / sigma0) exceeds one encoder count of joint 1 (2 pi / (1024 * 4 * ratio))."""
    from phantom_pin import Device

    text = " ".join((ROOT / "docs" / "simulation.md").read_text().split())   # lines joined
    device = Device()
    friction, stops = device.config.actuation.friction, device.config.limits.stops
    assert friction.uniform     # the doc quotes one level for every joint
    assert f"viscous {friction.viscous[0]:g} N m s/rad, Coulomb {friction.coulomb[0]:g} N m" in text
    assert f"K = {stops.stiffness:g} N m/rad, B = {stops.damping:g} N m s/rad" in text
    count = device.encoder_resolution[0]
    quoted = re.search(r"\(([0-9.e-]+) rad at joint 1\) unless σ0 < (\d+) N m/rad", text)
    assert abs(float(quoted[1]) / count - 1) < 5e-3                      # rounded to 3 digits
    assert int(quoted[2]) == round(friction.coulomb[0] / count)


def test_the_cli_page_says_what_ctrl_c_does_to_show_and_ros2():
    """docs/cli.md's Ctrl-C sentence (one line, exit 130) names its exceptions: `show`'s live
    viewer and the `ros2` node exit 0 on it, their normal stop (tests/cli/test_model.py's
    test_show_serves_on_loopback_until_interrupted runs show and sends SIGINT: exit 0)."""
    readme = " ".join((ROOT / "docs" / "cli.md").read_text().split())
    start = readme.index("Ctrl-C prints one line and exits with 130")
    sentence = readme[start:readme.index(". ", start)]
    assert "`show`'s live viewer and the `ros2` node run until Ctrl-C or SIGTERM and then exit 0" in sentence


def test_the_cli_pages_command_table_lists_every_command_and_the_newest_options():
    """docs/cli.md's command table has a row for every subcommand of the parser, and shows
    show --gimbal and urdf --convention driver."""
    from phantom_pin.cli.app import parser

    readme = (ROOT / "docs" / "cli.md").read_text()
    table = readme.split("## The commands at a glance")[1].split("\n\n")[1]
    rows = [line for line in table.splitlines() if line.startswith("| `phantom-pin")]
    commands = next(a for a in parser()._actions if a.dest == "command").choices
    for command in commands:
        assert any(re.search(rf"[ `]{command}[ `]", row.split("` |")[0] + "`") for row in rows), command
    assert any("show [" in row and "--gimbal" in row for row in rows)
    assert any("urdf -o" in row and "--convention driver" in row for row in rows)
