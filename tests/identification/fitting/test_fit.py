"""identification.fitting.fit: the Fit record's friction (the last six base parameters, in
FRICTION_NAMES' order) and its defaults, the Curves record frozen."""

import dataclasses

import numpy as np
import pytest

from phantom_pin.identification.fitting.fit import Curves, Fit
from phantom_pin.identification.structure import constants

REQUIRED = [field.name for field in dataclasses.fields(Fit)
            if field.default is dataclasses.MISSING and field.default_factory is dataclasses.MISSING]


def _fit(**values):
    return Fit(**{**dict.fromkeys(REQUIRED), **values})


def test_friction_is_the_last_six_base_parameters():
    """beta = (the report's eight constants, viscous1..3, coulomb1..3): friction gives the six
    friction values and their standard deviations, in constants.FRICTION_NAMES' order."""
    beta, sigma = np.arange(14.0), np.arange(14.0) / 100
    values, spread = _fit(beta=beta, sigma=sigma, names=constants.NAMES + constants.FRICTION_NAMES).friction
    np.testing.assert_array_equal(values, [8, 9, 10, 11, 12, 13])
    np.testing.assert_array_equal(spread, np.arange(8, 14) / 100)
    assert len(constants.NAMES + constants.FRICTION_NAMES) == 14


def test_the_records_defaults_and_frozen_fields():
    """A Fit with only its required fields: no problems, no delay, torques held, each score
    empty (a fresh dict per Fit); both records frozen."""
    a, b = _fit(), _fit()
    assert a.problems == () and a.delay == 0.0 and not a.delay_estimated and a.timing == "held"
    assert a.delay_cutoff == (20.0, {}) and a.closed_loop == "" and a.curves is None
    assert a.timing_residual == {} and a.timing_residual is not b.timing_residual
    with pytest.raises(dataclasses.FrozenInstanceError):
        a.delay = 1.0
    curves = Curves(*(np.zeros((2, 3)),) * 6)
    with pytest.raises(dataclasses.FrozenInstanceError):
        curves.t = None
