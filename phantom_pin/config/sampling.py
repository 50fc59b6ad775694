"""Seeded postures and states inside a configuration's limits: the one rejection sampler."""

from __future__ import annotations

import numpy as np

from phantom_pin.config.types import Limits
from phantom_pin.exceptions import ParameterFileError

#: Rounds of rejection sampling before sample_postures gives up: enough when the limits keep
#: more than about 1/2000 of the box.
_SAMPLING_ROUNDS = 1000


def sample_postures(limits: Limits, n: int, rng: np.random.Generator, margin: float = 0.0,
                    draws: int | None = None) -> np.ndarray:
    """``n`` postures (rad), (n, 3), uniform in the joint box intersected with the stops'
    box, ``margin`` (rad) inside every limit, the coupled stops included (Limits.slack):
    rejection sampling, ``draws`` per round (default 2 n + 16). ParameterFileError if the
    limits keep too little of the box."""
    lower = np.maximum(limits.lower, limits.stops.lower)
    upper = np.minimum(limits.upper, limits.stops.upper)
    draws = 2 * n + 16 if draws is None else draws
    theta = np.empty((0, 3))
    for _ in range(_SAMPLING_ROUNDS):
        draw = rng.uniform(lower, upper, (draws, 3))
        theta = np.concatenate([theta, draw[(limits.slack(draw) >= margin).all(axis=1)]])
        if len(theta) >= n:
            return theta[:n]
    coupled = limits.stops.coupled
    raise ParameterFileError(
        f"joint_limits.yaml: the limits {margin} rad inside (coupled stops theta2 - theta3 <= "
        f"{coupled.theta2_minus_theta3_max!r}, theta3 - theta2 <= {coupled.theta3_minus_theta2_max!r}) "
        f"keep too little of the joint box to draw {n} postures ({len(theta)} in {_SAMPLING_ROUNDS} rounds)")


def random_states(limits: Limits, n: int,
                  seed: int | np.random.Generator) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``n`` seeded states (theta, dtheta, ddtheta), each (n, 3): theta uniform inside every
    limit (sample_postures, rad); rates and accelerations normal with standard deviations
    2 rad/s and 20 rad/s^2. ``seed`` may be a Generator, to draw a long sequence in chunks."""
    rng = np.random.default_rng(seed)
    theta = sample_postures(limits, n, rng)
    return theta, rng.normal(0, 2, (n, 3)), rng.normal(0, 20, (n, 3))
