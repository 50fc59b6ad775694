"""identification.fitting.checks: the refusals that need no fit, on logs and torques built here
whose fault is known (angles in degrees, torques in mN m, a flipped sign, a constant torque, too
few samples), each naming the joint or argument at fault, and the refusal's summary line."""

import numpy as np
import pytest

from phantom_pin import Phantom
from phantom_pin.exceptions import LogError, PhantomPinError
from phantom_pin.identification.data.io import Log
from phantom_pin.identification.fitting import checks

PHANTOM = Phantom()


def _log(theta=None, tau=None, n=200):
    t = np.arange(n) / 100.0
    rng = np.random.default_rng(3)
    theta = np.tile([0.0, 0.3, 0.45], (n, 1)) + 0.05 * np.sin(t)[:, None] if theta is None else theta
    tau = rng.normal(size=(n, 3)) * 0.05 if tau is None else tau
    return Log(t, theta, tau)


def test_a_log_no_arithmetic_should_touch_is_refused_naming_its_joint():
    """Angles in degrees (theta1 at 30 deg: 30 rad, more than a turn past the stop), torques of
    2000 N m on joint 3, a constant torque on joints 1 and 3: each a LogError (a ValueError)
    naming the joint; the log as built passes."""
    checks.refuse_log(_log(), PHANTOM)
    degrees = _log().theta.copy()
    degrees[:, 0] = 30.0
    with pytest.raises(LogError, match="^theta1: .*28.4 rad beyond the stops.*in degrees") as refused:
        checks.refuse_log(_log(theta=degrees), PHANTOM)
    assert isinstance(refused.value, ValueError) and isinstance(refused.value, PhantomPinError)
    # theta2 at 40 deg read as rad: past its own stop (2.08 rad) and further past the coupled
    # stop theta2 - theta3 <= 65 deg (1.13 rad) wherever theta3 < 0.94 rad: that stop is named
    # (before: "theta4", the fourth stop coordinate's index)
    coupled = _log().theta.copy()
    coupled[:, 1] = 40.0
    assert (coupled[:, 2] < 0.94).all()
    with pytest.raises(LogError, match="^theta2 - theta3: .* rad beyond the stops"):
        checks.refuse_log(_log(theta=coupled), PHANTOM)
    huge = _log().tau.copy()
    huge[5, 2] = 2000.0
    with pytest.raises(LogError, match="^tau3: .*2e\\+03 N m"):
        checks.refuse_log(_log(tau=huge), PHANTOM)
    constant = _log().tau.copy()
    constant[:, [0, 2]] = 0.1
    with pytest.raises(LogError, match="^tau1, tau3: constant torques"):
        checks.refuse_log(_log(tau=constant), PHANTOM)


def test_too_few_samples_and_too_little_motion_are_refused():
    """refuse_motion: 49 kept samples are too short, 50 pass; a joint moving in 49 of 100 is
    named (joint 2), one moving in 50 is not."""
    checks.refuse_motion(np.ones((checks.MIN_SAMPLES, 3), bool), 20.0, 0.01)
    with pytest.raises(LogError, match="too short: 49 samples"):
        checks.refuse_motion(np.ones((checks.MIN_SAMPLES - 1, 3), bool), 20.0, 0.01)
    moving = np.ones((100, 3), bool)
    moving[:51, 1] = False
    moving[50:, 2] = False
    with pytest.raises(LogError, match=r"too little motion: joint\(s\) 2 move") as refused:
        checks.refuse_motion(moving, 20.0, 0.01)
    assert ", 3" not in str(refused.value).split("move")[0]


def test_the_torques_size_and_sign_against_the_prior():
    """torque_problems and before_fit on torques that are the prior's times a known scale: 1 and
    2.9 pass, 1000 on every joint is the unit (mN m), -1 on every joint the amplifier polarity,
    5 on joint 2 alone names tau2 (and only where that joint's torques follow the motion); a joint
    whose torques do not follow the motion (noise) is not judged by before_fit."""
    rng = np.random.default_rng(4)
    prior = rng.normal(size=(300, 3))
    follows = np.ones(3, bool)
    for scale in (1.0, 2.9, [0.34, 1.0, 2.0]):
        assert checks.torque_problems(prior * scale, prior, follows) == ([], [], [])
        assert checks.before_fit(prior * scale, prior) == []
    joints, unit, wrong = checks.torque_problems(1000 * prior, prior, follows)
    assert joints == [] and wrong == [0, 1, 2] and "1e+03 times" in unit[0] and "in mN m?" in unit[0]
    joints, unit, wrong = checks.torque_problems(-prior, prior, follows)
    assert "signs flipped" in unit[0] and wrong == [0, 1, 2]
    joints, unit, wrong = checks.torque_problems(prior * [1, 5, 1], prior, follows)
    assert unit == [] and wrong == [1] and len(joints) == 1 and joints[0].startswith("tau2: ")
    assert checks.torque_problems(prior * [1, 5, 1], prior, np.array([True, False, True]))[0] == []
    assert checks.before_fit(prior * [1, -1, 1], prior)[0].startswith("tau2: ")
    assert "sign is flipped" in checks.before_fit(prior * [1, -1, 1], prior)[0]
    unrelated = prior.copy()
    unrelated[:, 2] = rng.normal(size=300)
    assert checks.before_fit(unrelated * [1, 1, 5], prior) == []
    assert checks.before_fit(unrelated * 1000, prior) == []      # no unit named while a joint does not follow
    assert "in mN m?" in checks.before_fit(prior * 1000, prior)[0]


def test_the_refusal_names_the_first_problem_and_counts_the_rest():
    assert checks.refusal(["a", "b", "c"]) == "a (and 2 more)" and checks.refusal(("a",)) == "a"
    error = checks.RefusedError(["first", "second"])
    assert error.problems == ("first", "second") and isinstance(error, LogError)
    assert str(error) == "first (and 1 more); not identified (accept=True keeps the fit anyway)"
