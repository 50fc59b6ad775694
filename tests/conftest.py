"""Shared fixtures: one Phantom, and seeded random states inside the joint limits."""

import numpy as np
import pytest

from phantom_pin import Phantom, closed_form

N_STATES = 1000


@pytest.fixture(scope="session")
def phantom() -> Phantom:
    return Phantom()


@pytest.fixture(scope="session")
def limits() -> tuple[np.ndarray, np.ndarray]:
    p = closed_form.shipped_parameters()
    return np.array(p.lower), np.array(p.upper)


@pytest.fixture()
def states(limits):
    """N_STATES seeded (theta, dtheta, ddtheta): theta uniform inside the joint limits,
    rates and accelerations normal with 2 rad/s and 20 rad/s^2 standard deviations."""
    rng = np.random.default_rng(20261121)
    theta = rng.uniform(limits[0], limits[1], (N_STATES, 3))
    return theta, rng.normal(0, 2, (N_STATES, 3)), rng.normal(0, 20, (N_STATES, 3))


def relative_error(actual: np.ndarray, expected: np.ndarray) -> float:
    """max |actual - expected| / max |expected| over the whole array."""
    return float(np.abs(actual - expected).max() / np.abs(expected).max())
