"""Issue 42 (Hardening 5): each test names the defect it guards against and compares with
something independent of the code under test (the configuration files' own numbers, closed
forms, a second tool)."""

import numpy as np
import pytest

from phantom_pin import config
from phantom_pin.cli import main

TOUCH = config.read("touch")


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def bounds(lower, upper):
    """The warning's "[a b c]..[d e f]" of limits (rad), as warn_limits prints them."""
    return "[" + " ".join(f"{v:.6g}" for v in lower) + "]..[" + " ".join(f"{v:.6g}" for v in upper) + "]"


def test_show_on_the_touch_checks_the_arm_and_the_gimbal_against_their_own_ranges(tmp_path, capsys):
    """H1: `--model touch show --theta ... --html` failed with "operands could not be broadcast
    together with shapes (6,) (3,)" (the six-joint limits against three angles). M10: gimbal
    angles beyond the gimbal's range got no warning. The ranges are the configuration's."""
    arm, gimbal = TOUCH.limits, TOUCH.gimbal
    inside = (np.array(arm.lower) + np.array(arm.upper)) / 2
    code, out, err = run(capsys, "--model", "touch", "show", "--theta", *map(str, inside),
                         "--gimbal", "0.1", "0.2", "0.3", "--html", str(tmp_path / "in.html"))
    assert code == 0 and err == "" and out.startswith("wrote") and (tmp_path / "in.html").is_file(), err
    beyond = [0.0, 0.0, gimbal.upper[2] + 0.01]  # joint6 just past its stop
    code, out, err = run(capsys, "--model", "touch", "show", "--theta", *map(str, inside),
                         "--gimbal", *map(str, beyond), "--html", str(tmp_path / "gimbal.html"))
    assert code == 0 and err.count("\n") == 1, err
    assert "warning: gimbal" in err and bounds(gimbal.lower, gimbal.upper) in err, err
    above = [0.0, 0.0, arm.upper[2] + 0.01]
    code, out, err = run(capsys, "--model", "touch", "show", "--theta", *map(str, above),
                         "--html", str(tmp_path / "arm.html"))
    assert code == 0 and err.count("\n") == 1, err
    assert "warning: theta" in err and bounds(arm.lower, arm.upper) in err, err
