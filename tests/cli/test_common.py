"""The command line's shared options (--model, --config, --params, --set) before or after the
command alike, each once; simulate's format from the output file's extension. Against the
closed form (eq. 10 with the overridden length) and the files' own formats."""

import csv
import dataclasses
import json

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


@pytest.mark.parametrize("name, kind", [("run.csv", "csv"), ("run.json", "json"), ("RUN.CSV", "csv")])
def test_simulate_writes_the_format_of_the_extension(tmp_path, cli, name, kind):
    """Before: `simulate ... -o run.csv` wrote JSON into run.csv."""
    target = tmp_path / name
    code, _, _ = cli("simulate", "--theta0", "0.1", "0.3", "0.4", "--duration", "0.01", "-o", str(target))
    text = target.read_text()
    assert code == 0
    if kind == "csv":
        rows = list(csv.reader(line for line in text.splitlines() if not line.startswith("#")))   # the record
        assert rows[0][0] == "t [s]" and len(rows) == 12 and float(rows[-1][0]) == pytest.approx(0.01, abs=1e-15)
    else:
        assert len(json.loads(text)["t"]) == 11


@pytest.mark.parametrize("argv, message", [
    (["-o", "OUT/run.csv", "--format", "json"], "--format: json into"),
    (["-o", "OUT/run.json", "--format", "csv"], "--format: csv into"),
    (["-o", "OUT/run.txt"], "--output: "),
    (["-o", ""], "--output: empty"),
])
def test_simulate_refuses_a_format_that_contradicts_the_extension_before_the_run(tmp_path, cli, argv, message):
    args = [a.replace("OUT", str(tmp_path)) for a in argv]
    code, out, err = cli("simulate", "--theta0", "0.1", "0.3", "0.4", "--duration", "1e9", *args)
    assert code == 2 and out == "" and err.count("\n") == 1 and message in err, err   # 1e9 s: not run
    assert list(tmp_path.iterdir()) == []


def test_simulate_format_without_a_file_and_with_a_matching_extension(tmp_path, cli):
    code, out, _ = cli("simulate", "--theta0", "0.1", "0.3", "0.4", "--duration", "0.01", "--format", "csv")
    assert code == 0 and out.startswith("t [s],")
    target = tmp_path / "run.txt"
    code, _, _ = cli("simulate", "--theta0", "0.1", "0.3", "0.4", "--duration", "0.01", "--format", "json",
                     "-o", str(target))
    assert code == 0 and len(json.loads(target.read_text())["t"]) == 11


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
