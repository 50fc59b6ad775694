"""filtering.quiet_cutoff, the cutoff the delay is estimated at where a log's angles are noisy:
its noise shares against the noise measured in the filtered acceleration of a known motion."""

import numpy as np
import pytest
import scipy.signal

from phantom_pin.identification.data import io
from phantom_pin.identification.fitting import filtering

RATE, DURATION = 1000.0, 60.0


def _acceleration(theta, cutoff):
    """The filtered acceleration (rad/s^2) as filtering.filtered computes it, written out here:
    Butterworth forwards and backwards, central differences twice."""
    sos = scipy.signal.butter(filtering.FILTER_ORDER, cutoff, fs=RATE, output="sos")
    smooth = scipy.signal.sosfiltfilt(sos, theta, axis=0)
    return np.gradient(np.gradient(smooth, 1 / RATE, axis=0), 1 / RATE, axis=0)


@pytest.mark.parametrize("sigma", [5e-6, 1.5e-5, 6e-5])
def test_the_noise_share_is_the_noise_measured_in_the_filtered_acceleration(sigma):
    """A smooth motion (three sines per joint, 0.2-0.9 Hz, 0.05-0.2 rad) plus white noise of
    ``sigma`` rad on the angles (seeded): quiet_cutoff's share at each cutoff tried is the noise
    measured in the filtered acceleration (that of the noisy angles less that of the exact ones,
    standard deviation over the filtered acceleration's RMS, worst joint, the edges cut) within
    5 % of itself (measured: 0.8 % at 20 and 10 Hz, 3.8 % at 14 Hz; the estimate reads the noise
    from the angles alone), and the cutoff chosen is the highest whose measured share is within
    NOISE_SHARE, else the lowest (5e-6 rad: 20 Hz, 0.71 %; 1.5e-5 rad: 20 Hz 2.1 %, 14 Hz 0.90 %,
    chosen; 6e-5 rad: 8.5, 3.6 and 1.5 % at 20, 14 and 10 Hz, the last chosen)."""
    t = np.arange(int(DURATION * RATE) + 1) / RATE
    frequency = np.array([[0.2, 0.5, 0.9], [0.3, 0.6, 0.8], [0.25, 0.45, 0.7]])          # Hz, joint x sine
    amplitude = np.array([[0.2, 0.1, 0.05], [0.15, 0.1, 0.05], [0.1, 0.1, 0.05]])         # rad
    exact = 0.3 + (amplitude * np.sin(2 * np.pi * frequency * t[:, None, None] + 1.0)).sum(-1)
    noisy = exact + np.random.default_rng(0).normal(0.0, sigma, exact.shape)
    log = io.Log(t, noisy, np.zeros_like(noisy))
    chosen, shares = filtering.quiet_cutoff(log, 20.0)
    edge = int(filtering.EDGE * RATE)
    measured = {}
    for cutoff in shares:
        noise = (_acceleration(noisy, cutoff) - _acceleration(exact, cutoff))[edge:-edge]
        signal = _acceleration(noisy, cutoff)[edge:-edge]
        measured[cutoff] = float((noise.std(axis=0) / np.sqrt((signal**2).mean(axis=0))).max())
    print(sigma, shares, measured)
    assert shares == pytest.approx(measured, rel=0.05)
    quiet = [c for c in measured if measured[c] <= filtering.NOISE_SHARE]
    assert chosen == (quiet[0] if quiet else min(measured))
    assert list(shares) == [20.0, *filtering.CUTOFFS][:len(shares)]


def test_exact_angles_keep_the_fits_cutoff():
    """Angles without noise (a sine, exact to rounding): the delay is estimated at the fit's own
    cutoff, the only one tried, whatever it is (20 Hz; 40 Hz, above every one of CUTOFFS)."""
    t = np.arange(20001) / RATE
    theta = np.column_stack([0.2 * np.sin(2 * np.pi * 0.5 * t + k) for k in range(3)])
    log = io.Log(t, theta, np.zeros_like(theta))
    for highest in (20.0, 40.0):
        chosen, shares = filtering.quiet_cutoff(log, highest)
        assert chosen == highest and list(shares) == [highest] and shares[highest] < 1e-6
