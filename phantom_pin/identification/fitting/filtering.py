"""A log filtered for the fit: zero-phase low-pass, derivatives, the friction columns filtered
as the torques, the edges cut, decimated, and which joints' equations are fitted.

The positions (rad) are low-passed by a Butterworth filter run forwards and backwards
(scipy.signal.sosfiltfilt, no phase lag) and differentiated by central differences into dtheta
(rad/s) and ddtheta (rad/s^2). The torques get the same filter, and so do the friction columns
of the regressor, computed at the log's rate from dtheta (parallel filtering): both sides of
tau = Phi beta see the same distortion, so that the Coulomb reversals the filter smears in the
torque are smeared alike in the regressor (without it, viscous friction came out 5-33 % off,
depending on the cutoff). The rigid-body columns, smooth functions of a motion far below the
cutoff, pass the filter unchanged and are computed at the kept samples. The filter's edge
transients are cut and the samples decimated to about 5 times the cutoff.

The delay between positions and torques (timing.py) is estimated from a second filtering where
the log's angles are noisy (``quiet_cutoff``): at the highest of CUTOFFS, up to the fit's, at
which the angles' noise stays within NOISE_SHARE (1 %) of the filtered acceleration on every joint. The
filter differentiates the angles twice, so their noise (an encoder's steps) reaches the
acceleration column amplified about as the cutoff's 2.5th power; a servo loop's controller feeds
the same steps into the logged torques through its rate gain, and a torque read a little early
then cancels part of the acceleration's noise: the residual's delay estimate comes out early.
Measured on a lab's 60 s sum of sines with the CAD device's encoder quantization
(benchmarks/identification_figures.py): at 20 Hz the noise was 2.6 % of the acceleration and the
delay came out -0.56 ms (true 0), writing viscous friction 10.5 % high; estimated at 14 Hz
(1.05 %), -0.18 ms; at 10 Hz (0.45 %), 0.05 ms, and the fit at 20 Hz with it wrote friction within
1.4 %. The fit itself stays at the cutoff given: on the tests' lab logs with 1 % torque noise and
quantization, fitting at 10 Hz instead of 20 made the narrow log's written model worse (joint 2:
2.7 -> 8.2 % on 500 states). The noise is estimated from the angles alone: the third difference
of what the highest cutoff removes, whose standard deviation is sqrt(20) times a white noise's;
its share is that times the filter's noise gain (the root sum of squares of its impulse
response, filtered forwards and backwards and differentiated twice) over the filtered
acceleration's RMS.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from phantom_pin.config import Friction
from phantom_pin.exceptions import LogError
from phantom_pin.identification.data.io import Log
from phantom_pin.identification.data.timing import HOLD, lagged
from phantom_pin.identification.structure.structures import friction_block

#: The low-pass cutoff (Hz) of estimate, identify and ``identify --cutoff`` unless given.
CUTOFF = 20.0
#: Fewest periods of the cutoff the log must span (the filter's transients and edges).
MIN_CYCLES = 10.0
#: Filter order and edge cut (s).
FILTER_ORDER, EDGE = 4, 0.25
#: Fewest log samples per second per hertz of cutoff: central differences of a motion at the
#: cutoff err by (2 pi cutoff / rate)^2 / 6, 1.6 % at this ratio.
RATE_PER_CUTOFF = 20.0
#: A joint's equation is fitted only where its rate stays above MIN_SPEED (rad/s) over the
#: filter's span (1 / cutoff) either side (``estimate(min_speed=)``, ``--min-speed``): near rest
#: a joint may stick, and its friction is then whatever holds it, not the sliding law the
#: regressor's columns describe. Where a joint's friction has a Stribeck peak just after
#: breakaway, a higher bound leaves it out: measured on a lab's 60 s sum of sines
#: (benchmarks/identification_figures.py, CAD device, a 1.5x peak decaying over 0.05 rad/s) at
#: 0.01 rad/s 0.82 / 0.76 % held-out, viscous friction 34 % low; at 0.05 rad/s 0.20 / 0.30 %, 3.6 %
#: low; at 0.1 rad/s 0.11 / 0.06 %, 2.2 % low. Not the default: on the tests' 1 %-noise lab logs
#: 0.05 rad/s made a narrow log's joint 1 worse (5.9 -> 7.1 % on states) and the predicted
#: uncertainty of a wide one optimistic (0.15 % predicted, 0.66 % shown), the samples it drops
#: having carried the noise's share of the residual.
MIN_SPEED = 0.01
#: The cutoffs (Hz) quiet_cutoff tries below the fit's, highest first, and the share of each
#: joint's filtered acceleration RMS the angles' noise may reach at the one chosen (module doc).
CUTOFFS, NOISE_SHARE = (14.0, 10.0), 0.01


@dataclasses.dataclass(frozen=True)
class Samples:
    """The filtered log at its kept samples: theta (N, 3) rad, dtheta rad/s, ddtheta rad/s^2,
    tau N m, the regressor's friction columns filtered as tau, ``friction`` (N, 3, 6):
    viscous1..3 then coulomb1..3, and ``moving`` (N, 3): whether each joint's equation is
    fitted (its rate stays above MIN_SPEED over the filter's span around the sample);
    ``filtered_tau`` the filtered torques at every logged sample (N m, before the timing's and
    the delay's shift), ``index`` the kept samples' rows in the log, ``rate`` the log's (Hz):
    what timing.lagged reads the torques at another lag from."""

    theta: np.ndarray
    dtheta: np.ndarray
    ddtheta: np.ndarray
    tau: np.ndarray
    friction: np.ndarray
    moving: np.ndarray
    filtered_tau: np.ndarray
    index: np.ndarray
    rate: float

    def at(self, lag: float, scale: np.ndarray | float = 1.0) -> Samples:
        """These samples with the torques read ``lag`` seconds before them (timing.lagged),
        times ``scale`` (per joint)."""
        return dataclasses.replace(self, tau=scale * lagged(self.filtered_tau, self.rate, self.index, lag))


def _butterworth(cutoff: float, rate: float) -> np.ndarray:
    """The filter's second-order sections at ``cutoff`` (Hz) for a log at ``rate`` (Hz);
    LogError naming ``cutoff`` where the rate is too low for central differences at it."""
    if not 0 < cutoff * RATE_PER_CUTOFF <= rate:
        raise LogError(f"{cutoff:g} Hz needs a log at {RATE_PER_CUTOFF * cutoff:g} Hz or faster "
                       f"(this one: {rate:.4g} Hz; central differences need {RATE_PER_CUTOFF:g} samples per "
                       "second per hertz of cutoff); lower --cutoff or log faster", argument="cutoff")
    # imported here: scipy.signal takes 0.4 s, which every command line start paid
    import scipy.signal

    return scipy.signal.butter(FILTER_ORDER, cutoff, fs=rate, output="sos")


def _derivatives(theta: np.ndarray, rate: float) -> tuple[np.ndarray, np.ndarray]:
    """The rates (rad/s) and accelerations (rad/s^2) of low-passed angles ``theta`` (N, ...) rad
    at ``rate`` (Hz), by central differences."""
    dtheta = np.gradient(theta, 1.0 / rate, axis=0)
    return dtheta, np.gradient(dtheta, 1.0 / rate, axis=0)


def quiet_cutoff(log: Log, highest: float) -> tuple[float, dict[float, float]]:
    """(the cutoff chosen, Hz; each cutoff tried and its noise share: the largest over the joints
    of the angles' noise in the filtered acceleration over its RMS) of ``log``: the highest of
    ``highest`` (Hz, the fit's cutoff, valid for the log) and the CUTOFFS below it whose share is
    NOISE_SHARE or less, else the lowest of them the log's length allows (module doc)."""
    import scipy.signal

    rate, duration = log.rate, float(log.t[-1] - log.t[0])
    tried = [highest] + [c for c in CUTOFFS if c < highest and c * duration >= MIN_CYCLES]
    edge = int(np.ceil(EDGE * rate))
    inside = slice(edge, len(log.t) - edge)
    impulse = np.zeros(2 * int(np.ceil(rate)) + 1)
    impulse[len(impulse) // 2] = 1.0
    shares: dict[float, float] = {}
    for cutoff in tried:
        sos = _butterworth(cutoff, rate)
        smooth = scipy.signal.sosfiltfilt(sos, log.theta, axis=0)
        if cutoff == highest:         # the noise: what the highest cutoff removes
            noise = np.diff((log.theta - smooth)[inside], 3, axis=0).std(axis=0) / np.sqrt(20.0)     # rad, per joint
        gain = float(np.sqrt((_derivatives(scipy.signal.sosfiltfilt(sos, impulse), rate)[1] ** 2).sum()))  # 1/s^2/rad
        signal = np.sqrt((_derivatives(smooth, rate)[1][inside] ** 2).mean(axis=0))
        shares[cutoff] = float((noise * gain / np.maximum(signal, 1e-300)).max())
        if shares[cutoff] <= NOISE_SHARE:
            return cutoff, shares
    return tried[-1], shares


def filtered(log: Log, cutoff: float, law: Friction, timing: str = "held", delay: float = 0.0,
             min_speed: float = MIN_SPEED) -> Samples:
    """The log filtered at ``cutoff`` (Hz), with the friction columns of ``law`` (Friction.torque
    with unit coefficients), edges cut, decimated (module doc); ``timing`` (timing.TIMINGS);
    ``delay`` (s): the torques were logged that long after the positions they belong to, so
    the torque of the positions at t_k is read at t_k + delay (then the hold's half sample)."""
    rate = log.rate
    sos = _butterworth(cutoff, rate)
    # imported here: scipy.signal and scipy.ndimage take 0.4 s, which every command line start paid
    import scipy.ndimage
    import scipy.signal

    theta = scipy.signal.sosfiltfilt(sos, log.theta, axis=0)
    tau = scipy.signal.sosfiltfilt(sos, log.tau, axis=0)
    smooth = tau
    if timing == "held":
        # the torque logged at t_k acts until t_k+1 (zero-order hold): low-passed, it is the
        # smooth signal half a period late; read it at t_k - 1/(2 rate), halfway back (without
        # this, viscous friction came out up to 20 % low)
        tau = np.concatenate([tau[:1], 0.5 * (tau[1:] + tau[:-1])])
    dtheta, ddtheta = _derivatives(theta, rate)
    columns = scipy.signal.sosfiltfilt(sos, np.concatenate([dtheta, law.unit_coulomb().torque(dtheta)], axis=1),
                                       axis=0)
    edge = int(np.ceil(EDGE * rate))
    step = max(1, int(rate / (5 * cutoff)))
    keep = slice(edge, len(log.t) - edge, step)
    friction = friction_block(columns[keep])
    span = max(1, int(round(rate / cutoff)))
    slow = scipy.ndimage.maximum_filter1d((np.abs(dtheta) < min_speed).astype(np.uint8), 2 * span + 1, axis=0)
    index = np.arange(len(log.t))[keep]
    tau = tau[keep] if delay == 0 else lagged(smooth, rate, index, HOLD[timing] / rate - delay)
    return Samples(theta[keep], dtheta[keep], ddtheta[keep], tau, friction, ~slow[keep].astype(bool),
                   smooth, index, rate)
