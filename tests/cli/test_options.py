"""The command line's shared options (--model, --config, --params, --set) before or after the
command alike, each once; simulate's format from the output file's extension. Against the
closed form (eq. 10 with the overridden length) and the files' own formats."""

import csv
import dataclasses
import json

import numpy as np
import pytest

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
