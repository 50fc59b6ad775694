"""Joint rates and accelerations estimated from angles sampled at a fixed rate, as a servo loop
must: a first-order low-pass (``cutoff`` Hz) of the backward difference of the angles gives the
rate; the same low-pass of the backward difference of that rate gives the acceleration. At
1 kHz and 20 Hz the rate lags a motion by about 1 / (2 pi 20) = 8 ms, the acceleration by
twice that; the filters' gains per sample are alpha = 1 - exp(-2 pi cutoff / rate), exact for
a constant rate of change.

One estimator serves every servo path that compensates beyond gravity (the pyOpenHaptics
Compensator; docs/feel.md says what the estimates cost in transparency).
"""

from __future__ import annotations

import math

import numpy as np

from phantom_pin.exceptions import InvalidInputError

#: The low-pass's default cut-off (Hz): at 1 kHz it passes a hand's motion (a few Hz) and
#: attenuates an encoder's steps, differentiated, by the filter's gain.
CUTOFF = 20.0


class Estimator:
    """``update(theta)`` with the angles (rad, (3,)) of each sample, in order, at ``rate`` Hz:
    (rate rad/s, acceleration rad/s^2), both zero at the first sample (the loop starts at rest)."""

    def __init__(self, rate: float = 1000.0, cutoff: float = CUTOFF) -> None:
        for name, value in (("rate", rate), ("cutoff", cutoff)):
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0 < value < math.inf:
                raise InvalidInputError(f"expected a frequency > 0 Hz, got {value!r}", argument=name)
        if not cutoff < rate / 2:
            raise InvalidInputError(f"must be below half the rate ({rate / 2:g} Hz), got {cutoff!r}", argument="cutoff")
        self.period = 1.0 / float(rate)
        self.alpha = 1.0 - math.exp(-2.0 * math.pi * float(cutoff) * self.period)
        self.previous: np.ndarray | None = None
        self.rate = np.zeros(3)
        self.acceleration = np.zeros(3)

    def update(self, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The estimates after the sample ``theta`` (rad)."""
        if self.previous is not None:
            rate = self.rate + self.alpha * ((theta - self.previous) / self.period - self.rate)
            self.acceleration = self.acceleration + self.alpha * ((rate - self.rate) / self.period - self.acceleration)
            self.rate = rate
        self.previous = np.array(theta, dtype=float)
        return self.rate, self.acceleration
