"""What the commands share (cli/common.py): the options --model, --config, --params, --set
before or after the command alike, each once; the overrides and the files they name; the output
files (never half written, the umask); one line naming the option at fault. Against the closed
form (eq. 10 with the overridden length) and the files' own formats."""

import dataclasses
import json
import os
import stat

import numpy as np
import pytest
import yaml

from helpers import REPORT
from phantom_pin import closed_form as cf

THETA = [0.2, 0.3, 0.4]


@pytest.mark.parametrize("where", ["before", "after"])
def test_set_before_or_after_the_command_is_the_closed_form_with_it(cli, where):
    """Before: `phantom-pin --set l1=0.3 fk ...` answered "invalid choice: 'l1=0.3'"."""
    options = ["--set", "l1=0.3", "--set", "l2=0.2"]
    argv = [*options, "fk", *map(str, THETA), "--json"] if where == "before" else \
        ["fk", *map(str, THETA), "--json", *options]
    code, out, err = cli(*argv)
    expected = cf.forward_kinematics(THETA, dataclasses.replace(REPORT, l1=0.3, l2=0.2))
    assert code == 0 and err == ""
    np.testing.assert_allclose(json.loads(out)["g_st"], expected, rtol=0, atol=1e-12)


def test_set_on_both_sides_adds_up_and_params_before_the_command(tmp_path, cli):
    params = tmp_path / "lengths.yaml"
    params.write_text("l1: 0.25\nl2: 0.5\n")
    code, out, _ = cli("--params", str(params), "--set", "l2=0.2", "fk", *map(str, THETA), "--json",
                       "--set", "l1=0.3")
    expected = cf.forward_kinematics(THETA, dataclasses.replace(REPORT, l1=0.3, l2=0.2))
    assert code == 0
    np.testing.assert_allclose(json.loads(out)["g_st"], expected, rtol=0, atol=1e-12)


@pytest.mark.parametrize("argv, message", [
    (["--model", "touch", "--model", "premium_1_5", "info"], "--model: given twice; give it once"),
    (["--model", "touch", "info", "--model", "touch"], "--model: given before and after the command"),
    (["info", "--model", "touch", "--model", "premium_1_5_cad"], "--model: given twice; give it once"),
    (["--params", "a.yaml", "info", "--params", "b.yaml"], "--params: given before and after the command"),
    (["--config", ".", "info", "--config", "."], "--config: given before and after the command"),
])
def test_a_model_option_given_twice_is_refused_in_one_line(cli, argv, message):
    """Before: `--model touch --model premium_1_5 info` silently took the last one."""
    code, out, err = cli(*argv)
    assert code == 2 and out == "" and err.count("\n") == 1 and message in err, err


def test_the_model_option_after_the_command_chooses_the_model(cli):
    code, out, _ = cli("info", "--json", "--model", "touch")
    assert code == 0 and json.loads(out)["model"] == "touch"


def test_quiet_after_the_command_too(cli):
    code, out, err = cli("check", "-n", "10", "-q")
    assert code == 0 and "all checks pass" in out and err == ""


def test_show_refuses_an_empty_html_name_instead_of_serving(cli):
    """Before: `show --html ''` started the live viewer and blocked."""
    code, out, err = cli("show", "--html", "")
    assert code == 2 and out == "" and err == "phantom-pin: error: --html: empty; give a file name\n"


@pytest.mark.parametrize("text, message", [
    ("l1: 0.2\nl1: 0.3\n", "not valid YAML at line 2, column 1: the key 'l1' is given twice"),
    ("segment_a:\n  mass: 0.03\n  mass: 0.04\n", "not valid YAML at line 3, column 3: the key 'mass' is given twice"),
    ("segment_a:\n  mass: 0.03\nsegment_a.mass: 0.04\n", "segment_a.mass is given twice (nested and dotted)"),
])
def test_an_overlay_that_gives_one_number_twice_is_refused(tmp_path, cli, text, message):
    """An overlay that gives one number twice (a key twice in one mapping, or one number both
    nested and dotted) is refused in one line naming --params and the file, not the last taken.
    PyYAML itself reads such a file without a word (the premise)."""
    overlay = tmp_path / "overlay.yaml"
    overlay.write_text(text)
    yaml.safe_load(text)  # no error from PyYAML: it keeps the last
    code, out, err = cli("--params", str(overlay), "fk", "0", "0", "0")
    assert (code, out) == (2, "") and err == f"phantom-pin: error: --params: {overlay}: {message}\n", err


@pytest.mark.parametrize("argv, message", [
    (["urdf", "-o", "{tmp}/a.urdf", "--output", "{tmp}/b.urdf"], "--output: given twice; give it once"),
    (["simulate", "--theta0", "0", "0.3", "0.4", "--duration", "0.1", "-o", "{tmp}/a.json", "-o", "{tmp}/b.json"],
     "-o: given twice; give it once"),
    (["excite", "-o", "{tmp}/a.csv", "-o", "{tmp}/b.csv"], "-o: given twice; give it once"),
    (["--set", "l1=0.2", "fk", "0", "0", "0", "--set", "l1=0.3"], "--set: l1 given twice; give it once"),
])
def test_an_option_given_twice_is_refused_not_silently_the_last(tmp_path, cli, argv, message):
    """-o/--output, or one --set key, given twice is refused in one line with nothing written
    (as a second --model is), not silently the last. --params then --set of one key stays an
    override (the documented order)."""
    code, out, err = cli(*[a.replace("{tmp}", str(tmp_path)) for a in argv])
    assert (code, out, err) == (2, "", f"phantom-pin: error: {message}\n")
    assert list(tmp_path.iterdir()) == []
    (tmp_path / "p.yaml").write_text("l1: 0.25\n")
    code, out, _ = cli("--params", str(tmp_path / "p.yaml"), "--set", "l1=0.3", "fk", "0", "0", "0", "--json")
    assert code == 0 and json.loads(out) == json.loads(cli("--set", "l1=0.3", "fk", "0", "0", "0", "--json")[1])


@pytest.mark.parametrize("argv, message", [
    (["--set", "foo=1"], "foo: no parameter file has the key 'foo'"),
    (["--set", "motor.max_speed=1"], "qualify it, e.g. actuation.motor.max_speed"),
    (["--set", "kinematics.l4=1"], "kinematics.yaml has no key 'l4'"),
    (["--set", "l1=abc"], "--set: expected KEY=NUMBER"),
    (["--set", "segment_a=1"], "segment_a: not a number"),
    (["--set", "l1=-0.1"], "l1 must be positive"),
    (["--params", "/nonexistent/params.yaml"], "--params"),
])
def test_bad_overrides_give_one_line_and_exit_code_2(tmp_path, cli, argv, message):
    target = tmp_path / "phantom.urdf"
    code, _, err = cli("urdf", "-o", str(target), *argv)
    assert code == 2 and message in err and err.count("\n") == 1 and not target.exists()


@pytest.mark.parametrize("argv, message", [
    (["urdf", "-o", "/nonexistent_dir/x.urdf"], "--output: folder /nonexistent_dir does not exist"),
    (["urdf", "-o", "{tmp}", "--force"], "is a folder"),
    (["srdf", "-o", "{tmp}", "--force"], "is a folder"),
    (["show", "--html", "{tmp}", "--force"], "--html: "),
    (["dynamics", "--theta", "0", "0", "0", "--dtheta", "1e200", "1e200", "1e200", "--json"], "overflows"),
    (["check", "-n", "1.5"], "-n: expected a positive whole number"),
    (["ik", "0", "0.17", "0.17", "--branch", "left"], "invalid choice"),
])
def test_more_bad_arguments_give_one_line_and_exit_code_2(tmp_path, cli, argv, message):
    code, out, err = cli(*(a.format(tmp=tmp_path) for a in argv))
    assert code == 2 and message in err and err.count("\n") == 1 and out == ""


def test_binary_params_file_is_named(tmp_path, cli):
    params = tmp_path / "params.yaml"
    params.write_bytes(bytes(range(128, 256)))
    code, _, err = cli("urdf", "-o", str(tmp_path / "x.urdf"), "--params", str(params))
    assert code == 2 and "params.yaml: not a text file" in err and err.count("\n") == 1


def test_negative_numbers_in_scientific_notation_are_values(cli):
    code, out, _ = cli("fk", "-1e-3", "0", "0", "--json")
    assert code == 0
    np.testing.assert_allclose(json.loads(out)["g_st"], cf.forward_kinematics([-1e-3, 0, 0], REPORT), atol=1e-12)
    code, out, _ = cli("dynamics", "--theta", "-1e-3", "0.1", "0.2", "--dtheta", "-2E+0", "0", "-.5",
                       "--json")
    assert code == 0
    np.testing.assert_allclose(json.loads(out)["tau"], cf.inverse_dynamics([-1e-3, 0.1, 0.2], [-2, 0, -0.5],
                                                                           [0, 0, 0], REPORT), rtol=1e-9)


def test_every_command_takes_the_overrides(cli, tmp_path):
    """--set and --params reach every command's model: fk with l1, l2 changed follows eq. 10
    with them (written here); info reports the changed mass; check passes on the changed model."""
    params = tmp_path / "p.yaml"
    params.write_text("l1: 0.2\nsegment_a.mass: 0.03\n")
    code, out, _ = cli("fk", "0.3", "0.5", "0.7", "--params", str(params), "--set", "l2=0.15", "--json")
    tip = np.array(json.loads(out)["g_st"])[:3, 3]
    l1, l2, (t1, t2, t3) = 0.2, 0.15, (0.3, 0.5, 0.7)
    reach = l1 * np.cos(t2) + l2 * np.sin(t3)
    np.testing.assert_allclose(tip, [np.sin(t1) * reach, l2 - l2 * np.cos(t3) + l1 * np.sin(t2),
                                     -l1 + np.cos(t1) * reach], rtol=0, atol=1e-12)
    code, out, _ = cli("info", "--params", str(params), "--json")
    masses = {link["name"]: link["mass"] for link in json.loads(out)["links"]}
    assert code == 0 and masses["forearm_link"] == pytest.approx(0.03, rel=1e-12)
    code, out, _ = cli("check", "-n", "50", "--set", "l1=0.2")
    assert code == 0 and "all checks pass" in out
    code, _, err = cli("dynamics", "--theta", "0", "0", "0", "--set", "foo=1")
    assert code == 2 and err.count("\n") == 1 and "foo" in err


@pytest.mark.parametrize("argv, message", [
    (["ik", "1e308", "0", "0"], "position: [1.e+308 0.e+000 0.e+000] m is 1e+308 m from the shoulder, outside the "
                                "reachable shell [0.0450, 0.3850] m"),                       # 4 digits, not 309
    (["--set", "=0.2", "fk", "0", "0", "0"], "--set: expected KEY=NUMBER, got '=0.2' (no key)"),       # no key
    (["urdf", "-o", "/dev/full", "-f"], "--output: cannot write /dev/full (No space left on device)"),  # a failed write
    (["--config", "{tmp}", "info"], "{tmp}: not a configuration folder (it has none of kinematics.yaml, "),  # empty
    (["excite", "-o", "{tmp}/old.csv"], "--output: {tmp}/old.csv exists; use --force to overwrite it"),  # one wording
    (["urdf", "-o", "{tmp}/old.csv"], "--output: {tmp}/old.csv exists; use --force to overwrite it"),
])
def test_an_error_names_the_option_at_fault_in_one_readable_line(tmp_path, cli, argv, message):
    """An error names the option at fault in one readable line (exit 2, nothing overwritten): ik's
    distance to the shoulder in four significant digits (not 309 digits at 1e308), --set without
    a key as such, a write that fails by --output, a folder with none of the parameter files as
    not a configuration folder, an existing output with "use --force" in every command."""
    (tmp_path / "old.csv").write_text("kept\n")
    code, out, err = cli(*[a.replace("{tmp}", str(tmp_path)) for a in argv])
    assert (code, out) == (2, "") and err.count("\n") == 1
    assert err.startswith("phantom-pin: error: " + message.replace("{tmp}", str(tmp_path))), err
    assert (tmp_path / "old.csv").read_text() == "kept\n"


@pytest.mark.parametrize("argv, option", [(["identify", "{missing}", "-o", "{tmp}/id.yaml"], "LOG"),
                                          (["simulate", "--trajectory", "{missing}"], "--trajectory")])
def test_a_missing_log_or_trajectory_is_named_by_its_option(tmp_path, cli, argv, option):
    """A log or trajectory that cannot be read is named by its option (LOG, --trajectory) with the
    system's reason, in one line (not Python's errno text)."""
    missing = tmp_path / "missing.csv"
    code, out, err = cli(*[a.replace("{missing}", str(missing)).replace("{tmp}", str(tmp_path)) for a in argv])
    assert (code, out) == (2, "") and err == f"phantom-pin: error: {option}: {missing}: cannot read (No such file or " \
                                             "directory)\n"


@pytest.mark.parametrize("output, scene", [("model.xml", "/dev/full"), ("/dev/full", "scene.xml")])
def test_mjcf_writes_neither_file_when_one_cannot_be_written(tmp_path, cli, output, scene):
    """mjcf writes both of its files or neither: with either unwritable (a full device), the
    folder stays empty and one line names the option whose file failed."""
    paths = [p if p.startswith("/dev") else str(tmp_path / p) for p in (output, scene)]
    code, out, err = cli("mjcf", "-o", paths[0], "--scene", paths[1], "--force")
    option = "--scene" if scene.startswith("/dev") else "--output"
    assert (code, out, err) == (2, "", f"phantom-pin: error: {option}: cannot write /dev/full (No space left on "
                                       "device)\n")
    assert list(tmp_path.iterdir()) == []


def test_written_files_take_the_umask_and_an_overwritten_file_keeps_its_mode(tmp_path, cli):
    """The command line's files are staged beside their targets and renamed into place: a new
    file gets the mode open() would give it (0666 less the umask), an overwritten one keeps its
    own, a symbolic link is written through (as open() would), and no temporary file is left
    behind."""
    mask = os.umask(0o027)
    try:
        assert cli("mjcf", "-o", tmp_path / "m.xml", "--scene", tmp_path / "s.xml")[0] == 0
        os.chmod(tmp_path / "s.xml", 0o600)
        (tmp_path / "s.xml").write_text("old\n")
        assert cli("mjcf", "-o", tmp_path / "m.xml", "--scene", tmp_path / "s.xml", "--force")[0] == 0
    finally:
        os.umask(mask)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.xml", "s.xml"]
    assert stat.S_IMODE((tmp_path / "m.xml").stat().st_mode) == 0o640
    assert stat.S_IMODE((tmp_path / "s.xml").stat().st_mode) == 0o600
    assert "m.xml" in (tmp_path / "s.xml").read_text()
    (tmp_path / "link.xml").symlink_to(tmp_path / "m.xml")  # written through, as open() would
    (tmp_path / "m.xml").write_text("old\n")
    assert cli("mjcf", "-o", tmp_path / "link.xml", "--force")[0] == 0
    assert (tmp_path / "link.xml").is_symlink() and "<mujoco" in (tmp_path / "m.xml").read_text()
