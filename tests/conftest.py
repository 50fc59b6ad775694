"""Shared fixtures: one Phantom, and seeded random states inside the joint limits."""

import numpy as np
import pytest

from phantom_pin import Phantom, closed_form
from phantom_pin.parameters import random_states

N_STATES = 1000


@pytest.fixture(scope="session")
def phantom() -> Phantom:
    return Phantom()


@pytest.fixture(scope="session")
def limits() -> tuple[np.ndarray, np.ndarray]:
    p = closed_form.shipped_parameters()
    return np.array(p.lower), np.array(p.upper)


@pytest.fixture()
def states():
    """N_STATES seeded (theta, dtheta, ddtheta) inside the joint limits (parameters.random_states)."""
    return random_states(closed_form.shipped_parameters(), N_STATES, seed=20261121)


def relative_error(actual: np.ndarray, expected: np.ndarray) -> float:
    """max |actual - expected| / max |expected| over the whole array."""
    return float(np.abs(actual - expected).max() / np.abs(expected).max())
