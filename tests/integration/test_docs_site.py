"""The documentation site (mkdocs.yml, docs/): every code block of its pages and of the README
runs (or is named as one that cannot run here, and counted), and the command-line reference,
generated from the parser by docs/hooks.py, names every subcommand and every option."""

import importlib.util
import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

from phantom_pin.cli.app import parser

ROOT = Path(__file__).resolve().parents[2]
PAGES = sorted((ROOT / "docs").glob("*.md")) + [ROOT / "README.md"]
FENCE = re.compile(r"^( *)```([^\n`]*)\n(.*?)^\1```", re.S | re.M)
#: The fence languages that run in this test.
RUN = {"python", "bash"}
#: Those that name a block that cannot run here, with why, and how many there are: a new one must
#: be counted here on purpose (and a runnable block must not hide among them).
NOT_RUN = {"bash-ci": 2,       # the README's quick start: .ci/run runs it (checked below)
           "bash-norun": 7,    # needs a device, a ROS 2 install or a driver; phantom-pin lines parsed;
                               # docs/feel.md's reproduction (tests/device/test_feel.py and
                               # tests/cli/test_feel.py check what it prints)
           "python-norun": 2,  # the relay (the driver's omni_msgs); a pyOpenHaptics callback (a device,
                               # or the stand-in: tests/interfaces/openhaptics/test_compensator.py runs it)
           "c": 2,             # the lines inside an OpenHaptics servo callback (examples/openhaptics_gravity.c)
           "text": 5}          # formulas (cad.md, identification.md)


def blocks(language: str | None = None) -> list[tuple[str, str, str]]:
    """(page name, language, code) of every fenced block of the pages, in order."""
    found = []
    for page in PAGES:
        for match in FENCE.finditer(page.read_text(encoding="utf-8")):
            code = "\n".join(line[len(match[1]):] for line in match[3].splitlines())
            if language is None or match[2] == language:
                found.append((page.name, match[2], code))
    return found


def test_every_fence_language_is_run_or_counted():
    """A block in a language of neither list, or one more (or fewer) non-running block than
    counted, fails: the docs cannot gain a block that no test runs by accident."""
    counts: dict[str, int] = {}
    for _, language, _ in blocks():
        assert language in RUN or language in NOT_RUN, f"fence language {language!r}: run it or count it"
        counts[language] = counts.get(language, 0) + 1
    assert {k: counts.get(k, 0) for k in NOT_RUN} == NOT_RUN
    assert sum(counts.get(k, 0) for k in RUN) >= 13


def test_the_quick_start_blocks_are_what_ci_runs():
    ci = (ROOT / ".ci" / "run").read_text()
    quick = [code for _, _, code in blocks("bash-ci")]
    assert quick and all(code.strip() in ci for code in quick)


def _phantom_pin_lines(code: str) -> list[list[str]]:
    """The `phantom-pin` command lines of a block, comments and [optional parts] dropped."""
    lines = []
    for line in code.splitlines():
        line = re.sub(r"\[[^\]]*\]", "", line.split(" #")[0]).strip()
        if line.startswith("phantom-pin "):
            lines.append(shlex.split(line)[1:])
    return lines


def test_the_commands_of_the_blocks_that_do_not_run_parse():
    """What cannot run here (it needs a device's log or ROS 2) is still parsed by the real parser:
    a renamed command or option fails here."""
    commands = [argv for _, _, code in blocks("bash-norun") for argv in _phantom_pin_lines(code)]
    assert len(commands) >= 8
    for argv in commands:
        parser().parse_args(argv)


def _pages_with(language: str) -> list[str]:
    return sorted({name for name, _, _ in blocks(language)})


def _sandbox(tmp_path: Path) -> dict[str, str]:
    """A working folder with the repository's robots/ and benchmarks/ (the blocks' relative paths),
    and an environment whose phantom_pin is this tree's."""
    for name in ("robots",):
        (tmp_path / name).symlink_to(ROOT / name)
    env = dict(os.environ, PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""),
               PATH=str(Path(sys.executable).parent) + os.pathsep + os.environ["PATH"], MPLBACKEND="Agg")
    return env


@pytest.mark.parametrize("page", _pages_with("python"))
def test_the_python_blocks_of_a_page_run(tmp_path, page):
    """Every python block of a page, in order, in one interpreter (a block may use the names of
    the one before it, as a reader would run them), with warnings shown but no error."""
    code = "\n\n".join(code for name, _, code in blocks("python") if name == page)
    script = tmp_path / "blocks.py"
    script.write_text(code)
    result = subprocess.run([sys.executable, str(script)], cwd=tmp_path, env=_sandbox(tmp_path),
                            capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, f"{page}:\n{result.stderr[-3000:]}"


@pytest.mark.slow
@pytest.mark.parametrize("page", _pages_with("bash"))
def test_the_bash_blocks_of_a_page_run(tmp_path, page):
    code = "\n".join(code for name, _, code in blocks("bash") if name == page)
    result = subprocess.run(["bash", "-euo", "pipefail", "-c", code], cwd=tmp_path, env=_sandbox(tmp_path),
                            capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, f"{page}:\n{result.stderr[-3000:]}"


def _hooks():
    spec = importlib.util.spec_from_file_location("docs_hooks", ROOT / "docs" / "hooks.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_cli_reference_names_every_subcommand_and_option():
    """Against the parser: each subcommand has a section holding its help and every option string
    and positional of its own; the shared options are in theirs."""
    hooks = _hooks()
    top = parser()
    text = hooks.cli_reference(top)
    sections = dict(re.findall(r"^## `?([\w -]+?)`?\n(.*?)(?=^## |\Z)", text, re.S | re.M))
    shared = sections["Shared options"]
    subcommands = next(a for a in top._actions if a.dest == "command")
    helps = {a.dest: a.help for a in subcommands._choices_actions}
    assert set(sections) - {"Shared options"} == set(subcommands.choices)
    for name, command in subcommands.choices.items():
        section = sections[name]
        assert " ".join(helps[name].split()).replace("|", "\\|") in section, name
        for action in command._actions:
            if action.dest == "help":
                continue
            if not action.option_strings:
                assert f"`{action.metavar or action.dest}`" in section, (name, action.dest)
            for option in action.option_strings:
                where = shared if option in hooks.shared_options(top) else section
                assert f"`{option}`" in where, (name, option)


def test_the_command_table_lists_every_command():
    """The CLI page's table of commands (written by hand, beside the generated reference) has a
    row for every subcommand."""
    table = (ROOT / "docs" / "cli.md").read_text().split("## The commands at a glance")[1].split("\n\n")[1]
    rows = [line.split("` |")[0] + "`" for line in table.splitlines() if line.startswith("| `phantom-pin")]
    for command in next(a for a in parser()._actions if a.dest == "command").choices:
        assert any(re.search(rf"[ `]{command}[ `]", row) for row in rows), command


def test_the_frames_page_says_what_the_urdf_and_the_drivers_module_do():
    """docs/frames.md against the Touch's URDF (Pinocchio's frame placements at the zero posture)
    and phantom_pin.interfaces.conventions: frame s's axes are base_link's (y, z, x), as are the report's
    dynamics frame's, the tool frame's and the stylus's at zero; stylus_tip is 39 mm from the
    gimbal's centre; OpenHaptics' angles and torques map as the page writes them."""
    import numpy as np
    import pinocchio as pin

    from phantom_pin import describe, load
    from phantom_pin.interfaces import conventions

    text = " ".join((ROOT / "docs" / "frames.md").read_text().split())
    assert "x left, y up, z forward: base_link's (y, z, x)" in text
    assert "39 mm from the gimbal's centre" in text
    assert "θ = (−a1, a2, a3)" in text and "τ = (−T1, T2, T3) / 1000" in text
    robot = load(describe("touch"))
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, pin.neutral(robot.model))

    def pose(name):
        return data.oMf[robot.model.getFrameId(name)]

    axes = np.eye(3)[:, [1, 2, 0]]    # columns: s's x, y, z in base_link: base_link's y, z, x
    for frame in ("report_s", "report_dynamics", "tip", "stylus"):
        assert np.allclose(pose(frame).rotation, axes, atol=1e-12), frame
    assert np.linalg.norm(pose("stylus_tip").translation - pose("stylus").translation) == pytest.approx(0.039)
    assert np.allclose(pose("report_dynamics").translation, 0)    # the shoulder: base_link's origin
    assert np.allclose(conventions.theta_from_openhaptics([0.1, 0.2, 0.3]), [-0.1, 0.2, 0.3])
    assert np.allclose(conventions.tau_from_openhaptics_torque([1.0, 2.0, 3.0]), [-1e-3, 2e-3, 3e-3])


def test_the_readme_is_one_screen_that_points_into_the_site():
    """Issue 41: at most about 150 lines; a picture of each model; the build command that CI runs;
    every local link leads to a file that exists, and every page of the site's nav is reachable."""
    readme = (ROOT / "README.md").read_text()
    assert len(readme.splitlines()) <= 150
    for name in ("premium_1_5", "premium_1_5_cad", "touch"):
        assert f"(docs/pictures/{name}.png)" in readme
    assert "mkdocs build --strict" in readme and "mkdocs build --strict" in (ROOT / ".ci" / "run").read_text()
    links = re.findall(r"\]\(([^)#]+)\)", readme)
    local = [link for link in links if "://" not in link]
    assert local and all((ROOT / link).exists() for link in local), local
    nav = re.findall(r":\s*([\w-]+\.md)\s*$", (ROOT / "mkdocs.yml").read_text(), re.M)
    assert sorted(nav) == sorted(p.name for p in (ROOT / "docs").glob("*.md"))   # every page in the nav
