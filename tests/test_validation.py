"""phantom_pin._validation: the input checks every public function shares, each refusal an
InvalidInputError (a PhantomPinError and ValueError) naming the argument it was given; angle
wrapping against the definition (-pi, pi]; the output path's refusals; the rate helpers by hand."""

import math

import numpy as np
import pytest

from phantom_pin import InvalidInputError, PhantomPinError
from phantom_pin._validation import (
    as_state,
    as_states,
    finite_result,
    fixed_rate,
    output_path,
    same_batch,
    uneven,
    within_box,
    wrap_angle,
)


def test_states_keep_their_shape_and_batch_axes():
    """One state: (3,), no batch; a batch (2, 4, 3) keeps its leading axes; integers become
    floats; a list of lists reads as a batch."""
    one, batch = as_states([1, 2, 3], "theta")
    assert one.shape == (3,) and one.dtype == float and not batch
    many, batch = as_states(np.zeros((2, 4, 3)), "theta")
    assert many.shape == (2, 4, 3) and batch
    assert as_states([[0.0, 1.0, 2.0]], "theta")[1]
    np.testing.assert_array_equal(as_state((0.5, 1, -2), "dtheta"), [0.5, 1.0, -2.0])
    assert as_states(np.zeros((5, 6)), "q", width=6)[0].shape == (5, 6)


@pytest.mark.parametrize("value, match", [
    ([1.0, 2.0], r"shape \(3,\)"), (np.zeros((4, 2)), r"shape \(3,\)"), (1.0, r"shape \(3,\)"),
    (np.zeros((0, 3)), "at least one state"), ([[1, 2, 3], [1, 2]], "numbers"),
    ([True, False, True], "booleans"), (np.array([1, 2, 3], dtype=object) == 2, "booleans"),
    (np.array([1.0, True, 2.0], dtype=object), "booleans"), ([1.0, True, 2.0], "booleans"),
    ([[1.0, 2.0, 3.0], (1.0, False, 2.0)], "booleans"), ([1j, 0, 0], "complex"), (["a", "b", "c"], "numbers"),
    ([1.0, np.nan, 0.0], "NaN or inf"), ([[0, 0, 0], [0, 0, np.inf]], "NaN or inf"), (None, r"shape \(3,\)"),
])
def test_a_bad_state_is_refused_naming_its_argument(value, match):
    with pytest.raises(InvalidInputError, match=f"^ddtheta: .*{match}") as refused:
        as_states(value, "ddtheta")
    assert refused.value.argument == "ddtheta"
    assert isinstance(refused.value, ValueError) and isinstance(refused.value, PhantomPinError)


def test_one_state_refuses_a_batch_and_results_must_be_finite():
    with pytest.raises(InvalidInputError, match=r"^theta: expected one vector") as refused:
        as_state(np.zeros((1, 3)), "theta")
    assert refused.value.argument == "theta"
    same_batch(("a", "b"), np.zeros((2, 3)), np.ones((2, 3)))
    with pytest.raises(InvalidInputError, match=r"a \(2, 3\), b \(3, 3\)"):
        same_batch(("a", "b"), np.zeros((2, 3)), np.ones((3, 3)))
    result = np.ones(3)
    assert finite_result(result, "theta, dtheta") is result
    with pytest.raises(InvalidInputError) as refused:
        finite_result(np.array([1.0, np.inf, 0.0]), "theta, dtheta")
    assert refused.value.argument == "theta, dtheta"


def test_within_box_on_its_boundary_and_outside():
    lower, upper = np.array([-1.0, -1.0, -1.0]), np.array([1.0, 2.0, 3.0])
    assert within_box(upper, lower, upper) is True and within_box(lower, lower, upper) is True
    assert within_box([0.0, 2.0 + 1e-12, 0.0], lower, upper) is False
    np.testing.assert_array_equal(within_box([[0, 0, 0], [0, 0, 3.5]], lower, upper), [True, False])


def test_wrap_angle_maps_into_minus_pi_pi():
    """Every angle to the one of (-pi, pi] that differs by a whole number of turns (1e-12), pi
    itself kept and -pi to pi; angles inside returned bit for bit."""
    rng = np.random.default_rng(11)
    angles = rng.uniform(-50, 50, 1000)
    wrapped = wrap_angle(angles)
    assert ((wrapped > -np.pi) & (wrapped <= np.pi)).all()
    turns = (angles - wrapped) / (2 * np.pi)
    np.testing.assert_allclose(turns, np.round(turns), atol=1e-12)
    inside = angles[np.abs(angles) < np.pi]
    np.testing.assert_array_equal(wrap_angle(inside), inside)
    assert wrap_angle(np.array([np.pi]))[0] == np.pi and wrap_angle(np.array([-np.pi]))[0] == pytest.approx(np.pi)
    assert wrap_angle(np.array([3 * np.pi / 2]))[0] == pytest.approx(-np.pi / 2, abs=1e-15)


def test_output_path_refusals_name_the_argument(tmp_path):
    """A folder, a missing folder, an existing file without force: each refused naming ``out``
    and saying how to overwrite; force passes; /dev/null is written in place."""
    existing = tmp_path / "a.txt"
    existing.write_text("x")
    for path, match in ((tmp_path, "is a folder"), (tmp_path / "no" / "a.txt", "does not exist"),
                        (existing, "exists; use --force to overwrite")):
        with pytest.raises(InvalidInputError, match=match) as refused:
            output_path(path, False, "out", "--force")
        assert refused.value.argument == "out"
    assert output_path(existing, True, "out") == existing
    assert output_path(tmp_path / "b.txt", False, "out") == tmp_path / "b.txt"
    assert output_path("/dev/null", True, "out").as_posix() == "/dev/null"


def test_the_rate_and_its_evenness_by_hand():
    """11 samples over 0.01 s: 1000 Hz; intervals 1, 1, 1.2 ms (mean 1.0667 ms) stray by 12.5 %
    of their mean: uneven at a 10 % tolerance, not at 15 %."""
    assert fixed_rate(np.linspace(2.0, 2.01, 11)) == pytest.approx(1000.0, rel=1e-12)
    step = np.array([1.0, 1.0, 1.2]) * 1e-3
    assert math.isclose(np.abs(step - step.mean()).max() / step.mean(), 0.125)
    assert uneven(step, 0.10) and not uneven(step, 0.15)
