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
#: Below this estimated rate (rad/s) a joint is taken at rest by the compensations beyond gravity:
#: no Coulomb term (a compensation that pushed a resting joint would start it moving) and no
#: inertia while every joint is (docs/feel.md measures the choice).
REST = 0.01


class Estimator:
    """``update(theta)`` with the angles (rad, (3,)) of each sample, in order, at ``rate`` Hz:
    (rate rad/s, acceleration rad/s^2), both zero at the first sample (the loop starts at rest)."""

    def __init__(self, rate: float = 1000.0, cutoff: float = CUTOFF) -> None:
        for name, value in (("rate", rate), ("cutoff", cutoff)):
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0 < value < math.inf:
                raise InvalidInputError(f"expected a frequency > 0 Hz, got {value!r}", argument=name)
        if not cutoff < rate / 2:
            raise InvalidInputError(f"must be below half the rate ({rate / 2:g} Hz), got {cutoff!r}", argument="cutoff")
        self.period, self.cutoff = 1.0 / float(rate), float(cutoff)
        self.alpha = 1.0 - math.exp(-2.0 * math.pi * self.cutoff * self.period)
        self.previous: np.ndarray | None = None
        self.time: float | None = None
        self.rate = np.zeros(3)
        self.acceleration = np.zeros(3)

    def _step(self, theta: np.ndarray, period: float, alpha: float) -> None:
        rate = self.rate + alpha * ((theta - self.previous) / period - self.rate)
        self.acceleration = self.acceleration + alpha * ((rate - self.rate) / period - self.acceleration)
        self.rate = rate

    def update(self, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The estimates after the sample ``theta`` (rad), one period after the last."""
        if self.previous is not None:
            self._step(theta, self.period, self.alpha)
        self.previous = np.array(theta, dtype=float)
        return self.rate, self.acceleration

    def update_at(self, theta: np.ndarray, time: float | None) -> tuple[np.ndarray, np.ndarray]:
        """The estimates after the sample ``theta`` (rad) taken at ``time`` (s, a message's stamp):
        the period is the time since the last sample, the gain 1 - exp(-2 pi cutoff period); a
        sample at the same time or earlier (a burst with one stamp) replaces the last without a
        step. InvalidInputError naming ``time`` for a time that is not finite."""
        if time is None or not math.isfinite(time):
            raise InvalidInputError("the estimates need each state's time (s)", argument="time")
        if self.previous is not None and self.time is not None and time > self.time:
            period = time - self.time
            self._step(theta, period, 1.0 - math.exp(-2 * math.pi * self.cutoff * period))
        self.time, self.previous = float(time), np.array(theta, dtype=float)
        return self.rate, self.acceleration
