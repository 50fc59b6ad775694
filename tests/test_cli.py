"""The phantom-pin command line: outputs against closed_form, exit codes, --force."""

import json

import numpy as np
import pytest

from phantom_pin import closed_form as cf
from phantom_pin.cli import main
from phantom_pin.paths import URDF_PATH


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_check_passes_and_reports_every_method(capsys):
    code, out, _ = run(capsys, "check", "-n", "200", "--json")
    report = json.loads(out)
    assert code == 0 and report["passed"] and len(report["checks"]) == 8


def test_fk_and_ik_agree_with_the_closed_form(capsys):
    theta = [0.2, 0.3, 0.4]
    code, out, _ = run(capsys, "fk", *map(str, theta), "--json")
    assert code == 0
    np.testing.assert_allclose(json.loads(out)["g_st"], cf.forward_kinematics(theta), atol=1e-12)
    position = cf.forward_kinematics(theta)[:3, 3]
    code, out, _ = run(capsys, "ik", *(str(float(x)) for x in position), "--json")
    np.testing.assert_allclose(json.loads(out)["theta"], theta, atol=1e-9)


def test_dynamics_agrees_with_the_closed_form(capsys):
    code, out, _ = run(capsys, "dynamics", "--theta", "0.1", "0.2", "0.3", "--dtheta", "1", "2", "3",
                       "--ddtheta", "0", "1", "0", "--json")
    data = json.loads(out)
    np.testing.assert_allclose(data["tau"], cf.inverse_dynamics([0.1, 0.2, 0.3], [1, 2, 3], [0, 1, 0]), rtol=1e-9)
    np.testing.assert_allclose(data["M"], cf.mass_matrix([0.1, 0.2, 0.3]), rtol=1e-9)


def test_info_lists_the_report_masses(capsys):
    code, out, _ = run(capsys, "info", "--json")
    masses = {link["name"]: link["mass"] for link in json.loads(out)["links"]}
    assert masses == {"turret_link": 0.35, "upper_arm_link": 0.2359, "crank_link": 0.1906,
                      "lower_bar_link": 0.0249, "forearm_link": 0.0202}


@pytest.mark.parametrize("argv, message", [
    (["ik", "0", "0.3", "0.3"], "outside the reachable shell"),
    (["fk", "0", "0"], "required"),
    (["fk", "0", "nan", "0"], "theta: contains NaN"),
    (["check", "-n", "0"], "-n"),
    (["bogus"], "invalid choice"),
])
def test_bad_arguments_give_one_line_and_exit_code_2(capsys, argv, message):
    code, _, err = run(capsys, *argv)
    assert code == 2 and message in err and err.count("\n") == 1


def test_urdf_refuses_to_overwrite_without_force(tmp_path, capsys):
    target = tmp_path / "phantom.urdf"
    assert run(capsys, "urdf", "--output", str(target))[0] == 0
    assert target.read_text() == URDF_PATH.read_text()
    target.write_text("keep me")
    code, _, err = run(capsys, "urdf", "--output", str(target))
    assert code == 2 and "--force" in err and target.read_text() == "keep me"
    assert run(capsys, "urdf", "--output", str(target), "--force", "--prefix", "r_")[0] == 0
    assert 'name="r_joint1"' in target.read_text()
