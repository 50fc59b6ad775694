"""Estimation: zero-phase filtering, weighted least squares of the base parameters, the nearest
physically consistent parameters, and the checks that decide whether they may be written.

1. The positions (rad) are low-passed by a Butterworth filter run forwards and backwards
   (scipy.signal.sosfiltfilt, no phase lag) and differentiated by central differences into
   dtheta (rad/s) and ddtheta (rad/s^2). The torques get the same filter, and so do the
   friction columns of the regressor, computed at the log's rate from dtheta (parallel
   filtering): both sides of tau = Phi beta see the same distortion, so that the Coulomb
   reversals the filter smears in the torque are smeared alike in the regressor (without
   it, viscous friction came out 5-33 % off, depending on the cutoff). The rigid-body
   columns, smooth functions of a motion far below the cutoff, pass the filter unchanged
   and are computed at the kept samples. The filter's edge transients are cut and the
   samples decimated to about 5 times the cutoff.
2. beta by ordinary least squares, then weighted by the inverse residual standard deviation
   of each joint (Gauss-Markov): the log's information Phi_w^T Phi_w / s^2. With the prior
   (prior.py: the configuration's own base parameters as the mean, a stated covariance P), the
   Gauss-Markov estimate with that prior: covariance (Phi_w^T Phi_w / s^2 + P^-1)^-1, equal to
   the log alone's s^2 (Phi_w^T Phi_w)^-1 where the log excites everything, the prior's where
   it excites nothing. The base regressor's condition number (columns scaled to unit norm) is
   a diagnostic only: the fit is judged by the torques it predicts (prediction.py).
   With ``gains`` (the default), each joint's torque gain relative to joint 1 is estimated
   with beta (_solve_gains, a prior of 1 +- GAIN_SPREAD): the log's tau_j times g_j is the
   joint's torque in joint 1's scale (a torque constant, amplifier gain or transmission ratio
   off on one joint). Every link's parameters appear in several joints' equations (joint 1's
   holds every link), so one joint's scale against the others is in the log; the overall
   scale is not (all torques and all parameters scaled alike fit equally), hence joint 1 as
   the reference. A gain is corrected where the log shows it differs from 1 (by more than
   GAIN_NOTED and GAIN_EVIDENCE standard deviations), and beta estimated again with the
   others at 1.
3. physical.nearest: the structure's parameters x (structures.py) whose base parameters are
   nearest to beta in the covariance's metric, with every link physical and friction >= 0.
4. The checks (``Fit.problems``, each one line): a model that predicts the log worse than the
   prior, torques unrelated to the motion, a projection that moves an estimate far or flips
   its sign, negative friction, torques whose size or sign disagree with the model's, a joint
   whose gain is negative (amplifier polarity) or outside GAIN_BOUNDS (a unit), angles far
   beyond the stops. The gains are reported (``Fit.gain_lines``); those corrected, with what
   to write into the driver (``Fit.gain_warning``).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

import numpy as np
import scipy.linalg

from phantom_pin.config import Friction
from phantom_pin.dynamics.model import Phantom
from phantom_pin.exceptions import InvalidInputError, LogError
from phantom_pin.identification import prior as priors
from phantom_pin.identification.io import Log
from phantom_pin.identification.prediction import Prediction, judge
from phantom_pin.identification.structures import STRUCTURES, Structure, friction_block

#: Fewest periods of the cutoff the log must span (the filter's transients and edges).
MIN_CYCLES = 10.0
#: Filter order and edge cut (s).
FILTER_ORDER, EDGE = 4, 0.25
#: Fewest log samples per second per hertz of cutoff: central differences of a motion at the
#: cutoff err by (2 pi cutoff / rate)^2 / 6, 1.6 % at this ratio.
RATE_PER_CUTOFF = 20.0
#: Largest residual RMS of a joint, as a share of its torque RMS, that a usable log leaves
#: (a device's log leaves 0.3-3 %; torques unrelated to the motion, 50-100 %).
MAX_RESIDUAL_SHARE = 0.15
#: A base parameter the physical projection moves by more than this many standard deviations
#: and more than SHIFT_SHARE of its value means the estimate is not of a physical arm.
MAX_SHIFT_SIGMA, SHIFT_SHARE = 10.0, 0.1
#: The logged torques fit the model best scaled by s: refused outside these bounds (a unit).
TORQUE_SCALE = (1 / 3, 3.0)
#: The prior's standard deviation of each joint's torque gain relative to joint 1 (module doc,
#: step 2): a torque constant or amplifier gain is specified to a few percent, a transmission
#: ratio misread (11.2 for 11.6) is 3.5 % off; the log decides (excite's trajectory: +-0.002-0.1 %;
#: a lab's 60 s sum of sines, which moves joint 1 little: +-0.5 %).
GAIN_SPREAD = 0.05
#: A relative gain outside these bounds is no tolerance but a mistake (a unit, another joint's
#: ratio): refused; a negative one is a flipped amplifier.
GAIN_BOUNDS = (0.5, 2.0)
#: A gain is corrected (and the driver told: Fit.gain_warning) where the log shows it differs
#: from 1: by more than GAIN_NOTED and GAIN_EVIDENCE standard deviations; else it stays 1 and
#: the estimate is only reported. Both bounds, because in a closed loop the torque noise moves
#: the joints it drives, which biases the estimate beyond its standard deviation: measured -0.5
#: to -0.9 % on 60 s sum-of-sines logs with 1 % torque noise (1-1.7 sigma), up to 3.5 sigma on
#: excite's 10 s trajectory with 2 mN m, and -0.45 to -0.57 % (4-5 sigma) on excite's 20 s
#: trajectory with 10 mA of current noise; correcting such a gain cost 0.3-0.9 % of held-out
#: accuracy where the drives were right. A torque constant 2 % off or a ratio misread (3.5 %)
#: is well beyond both.
GAIN_NOTED, GAIN_EVIDENCE = 0.01, 4.0
#: Gauss-Newton steps of the gains at most, and the change of a gain's inverse that ends them.
GAIN_ITERATIONS, GAIN_TOLERANCE = 20, 1e-10
#: Angles further than this (rad) beyond the stops are not of the arm.
BEYOND_STOPS = 0.2
#: The report's structure needs the general model when it leaves more than this times the
#: general model's residual on some joint.
NEEDS_GENERAL = 1.2


@dataclasses.dataclass(frozen=True)
class Samples:
    """The filtered log at its kept samples: theta (N, 3) rad, dtheta rad/s, ddtheta rad/s^2,
    tau N m, the regressor's friction columns filtered as tau, ``friction`` (N, 3, 6):
    viscous1..3 then coulomb1..3, and ``moving`` (N, 3): whether each joint's equation is
    fitted (its rate stays above MIN_SPEED over the filter's span around the sample);
    ``filtered_tau`` the filtered torques at every logged sample (N m, before the timing's and
    the delay's shift), ``index`` the kept samples' rows in the log, ``rate`` the log's (Hz):
    what ``lagged`` reads the torques at another lag from."""

    theta: np.ndarray
    dtheta: np.ndarray
    ddtheta: np.ndarray
    tau: np.ndarray
    friction: np.ndarray
    moving: np.ndarray
    filtered_tau: np.ndarray | None = None
    index: np.ndarray | None = None
    rate: float = 0.0


@dataclasses.dataclass(frozen=True)
class Fit:
    """Result of ``estimate``.

    ``structure`` ("general" or "report"); ``names``, ``units``: the base parameters, each a
    sum of physical parameters; ``beta``, ``sigma``: their estimates and standard deviations;
    ``rms``: the residual RMS per joint (N m) of beta, ``written_rms`` of the written
    parameters, ``torque_rms`` the torque's RMS (N m); ``condition`` of the base regressor
    (columns scaled to unit norm); ``samples`` used; ``x``: the physical parameters
    (Structure.names: the structure's, then viscous1..3 N m s/rad, coulomb1..3 N m),
    ``written`` = their beta, ``overrides`` their --params keys (without friction: overlays.overlay);
    ``comparison``: (name, residual RMS per joint, N m) of the other structure, or None;
    ``gains`` (3,): each joint's torque gain relative to joint 1 as corrected (the log's tau_j
    times gains_j is the torque the model predicts; joint 1's is 1; 1 where not corrected),
    ``gains_estimated``: (estimates (3,), standard deviations (3,)), all 1 and 0 when not
    estimated, ``ratios`` the model's transmission ratios (None: not public),
    for the hint of a misread one; ``problems``: why the result should not be
    written (one line each; empty for a usable log). ``beta`` and ``sigma`` are the estimate
    with the prior (module doc, step 2): ``prior_beta`` the prior's base parameters, ``log_beta``
    and ``log_sigma`` the log's alone (inf where it leaves a direction unconstrained), ``log_rms``
    its residual RMS per joint (N m: whether the torques follow the motion at all);
    ``prediction``: the predicted torque uncertainty of the written parameters
    (prediction.Prediction). ``delay`` (s): how long after their positions the torques were
    logged, corrected for in the fit; ``delay_estimated``: whether it came from the log;
    ``timing`` the torque timing fitted (TIMINGS); ``timing_residual``: each timing's weighted
    residual (the sum over the joints of the residual's mean square over the torque's, at zero
    delay when it is estimated, else at the given one), the smaller fitting the log better."""

    structure: str
    names: tuple[str, ...]
    units: tuple[str, ...]
    beta: np.ndarray
    sigma: np.ndarray
    rms: np.ndarray
    written_rms: np.ndarray
    torque_rms: np.ndarray
    condition: float
    samples: int
    x: np.ndarray
    written: np.ndarray
    overrides: dict
    comparison: tuple[str, np.ndarray] | None
    gains: np.ndarray
    gains_estimated: tuple[np.ndarray, np.ndarray]
    problems: tuple[str, ...]
    prior_beta: np.ndarray
    log_beta: np.ndarray
    log_sigma: np.ndarray
    log_rms: np.ndarray
    prediction: Prediction
    delay: float = 0.0
    delay_estimated: bool = False
    timing: str = "held"
    timing_residual: dict[str, float] = dataclasses.field(default_factory=dict)
    ratios: tuple[float, float, float] | None = None

    def timing_lines(self) -> list[str]:
        """The delay (estimated or given, ms) and which timing fits the log better, one line each."""
        how = "estimated from the log" if self.delay_estimated else "given"
        lines = [f"delay between positions and torques: {1e3 * self.delay:.3f} ms ({how}; the torques are read "
                 f"that long after their positions, then the {self.timing} timing's lag)"]
        if len(self.timing_residual) == 2:
            best = min(self.timing_residual, key=lambda name: self.timing_residual[name])
            at = "no delay" if self.delay_estimated else f"the given {1e3 * self.delay:.3g} ms delay"
            lines.append(f"torque timing: {best} fits the log better with {at} (weighted residual: "
                         + ", ".join(f"{name} {100 * np.sqrt(value / 3):.3g} %" for name, value in
                                     self.timing_residual.items())
                         + f" of the torque RMS); identified as {self.timing}"
                         + ("; the estimated delay absorbs the timings' half-sample difference" if
                            self.delay_estimated else ""))
        return lines

    def timing_warning(self) -> str | None:
        """One line when the timing given fits the log worse than the other by more than
        TIMING_MARGIN of its weighted residual, else None."""
        if len(self.timing_residual) != 2:
            return None
        other = next(name for name in self.timing_residual if name != self.timing)
        chosen, alternative = self.timing_residual[self.timing], self.timing_residual[other]
        if chosen <= (1 + TIMING_MARGIN) * alternative:
            return None
        return (f"--torque-timing {self.timing} fits the log worse than {other} (weighted residual "
                f"{chosen / alternative:.3g} times, more than {1 + TIMING_MARGIN:g})"
                + (f" with no delay: the estimated delay, {1e3 * self.delay:.3f} ms, takes up the half sample "
                   f"between them; if the log has no delay, identify with --torque-timing {other}"
                   if self.delay_estimated else f"; identify with --torque-timing {other}"))

    def gain_lines(self) -> list[str]:
        """The joints' torque gains relative to joint 1, as estimated (the corrected ones as
        applied: estimated again with the others at 1) and what became of them, one line."""
        values, sigma = self.gains_estimated
        if not sigma.any():
            return ["torque gains: not estimated (--fixed-gains / gains=False): the log's torques taken as they are"]
        return ["torque gains relative to joint 1 (the log's torques times these are the model's): " + ", ".join(
            f"joint{j + 1} " + (f"{self.gains[j]:.6g} +- {sigma[j]:.2g} (corrected in the written model)"
                                if self.gains[j] != 1 else f"{values[j]:.6g} +- {sigma[j]:.2g} (within "
                                f"{GAIN_EVIDENCE:g} standard deviations or {100 * GAIN_NOTED:g} % of 1: kept at 1)")
            for j in (1, 2))]

    def gain_warning(self) -> str | None:
        """One line naming the gains corrected (what to write into the driver) and those kept at 1
        that the estimate puts more than GAIN_NOTED from it (the log cannot tell), else None."""
        values, sigma = self.gains_estimated
        off = [j for j in (1, 2) if self.gains[j] != 1 and GAIN_BOUNDS[0] <= self.gains[j] <= GAIN_BOUNDS[1]]
        unsure = [j for j in (1, 2) if self.gains[j] == 1 and sigma[j] > 0 and abs(values[j] - 1) > GAIN_NOTED]
        parts = []
        if off:
            hint = "" if self.ratios is None else " (or were they converted with transmission ratio " + ", ".join(
                f"{self.ratios[j] / self.gains[j]:.4g} instead of the model's {self.ratios[j]:.4g}" for j in off) + "?)"
            parts.append(" and ".join(f"tau{j + 1} is {1 / self.gains[j]:.4g} times" for j in off)
                         + " joint 1's torque scale (gain " + ", ".join(f"{self.gains[j]:.4g}" for j in off)
                         + "): corrected in the written model; multiply " + " and ".join(
                             f"joint {j + 1}'s torque constant in your driver by {self.gains[j]:.4g}" for j in off)
                         + f" so that its commands are the model's torques{hint}")
        if unsure:
            parts.append(", ".join(f"joint {j + 1}'s torque gain ({values[j]:.4g} +- {sigma[j]:.2g})" for j in unsure)
                         + f": kept at 1, the log cannot show it differs (needs {GAIN_EVIDENCE:g} standard "
                         "deviations); a log that moves joint 1 more (phantom-pin excite) would tell")
        return "; ".join(parts) or None

    @property
    def friction(self) -> tuple[np.ndarray, np.ndarray]:
        """(estimates, standard deviations) of viscous1..3 (N m s/rad) and coulomb1..3 (N m)."""
        return self.beta[-6:], self.sigma[-6:]

    def recommendation(self) -> str | None:
        """One line if the log shows the general model is needed (the report's structure leaves
        more than NEEDS_GENERAL times its residual on a joint), else None."""
        if self.comparison is None:
            return None
        general, report = (self.log_rms, self.comparison[1]) if self.structure == "general" else \
            (self.comparison[1], self.log_rms)          # both the log alone's fits
        ratio = float((report / general).max())
        if ratio <= NEEDS_GENERAL:
            return None
        return (f"the report's structure leaves up to {ratio:.2f} times the general model's residual (threshold "
                f"{NEEDS_GENERAL}): this device has products of inertia or off-axis centres of mass; "
                + ("keep the general structure's result" if self.structure == "general"
                   else "identify with --structure general"))


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
#: How a log's torques relate to its times: "held", commands each applied from its sample to the
#: next (a servo loop's zero-order hold: the default), or "sampled", the torque at that instant
#: (a torque sensor, or torques computed from the motion).
TIMINGS = ("held", "sampled")
#: The lag (in samples) of each timing's torque behind the positions it belongs to.
HOLD = {"held": 0.5, "sampled": 0.0}
#: The delays (s) the estimate searches: torques logged up to 5 ms before or after the
#: positions they belong to (a servo loop at 1 kHz logs within a few samples); found on a grid
#: of GRID_STEP s, then refined by a parabola through the grid's best three (sub-sample).
DELAY_BRACKET, GRID_STEP = (-5e-3, 5e-3), 2.5e-4
#: The delays (s) estimate accepts when given: from the bracket's start to a tenth of a second
#: (less than the filter's edge cut, EDGE: the shifted torques stay inside the log).
DELAY_RANGE = (DELAY_BRACKET[0], 0.1)
#: The timing given fits "markedly" worse than the other when its weighted residual (the sum
#: of the joints' squared residual shares) exceeds the other's by this share: then a warning.
TIMING_MARGIN = 0.05


def delay_argument(delay: object) -> float | None:
    """``delay`` (s) checked: None (estimate it) or a finite number in DELAY_RANGE;
    InvalidInputError naming ``delay`` otherwise."""
    if delay is None:
        return None
    if isinstance(delay, bool) or not isinstance(delay, (int, float, np.floating, np.integer)) \
            or not np.isfinite(delay) or not DELAY_RANGE[0] <= delay <= DELAY_RANGE[1]:
        raise InvalidInputError(f"expected seconds between {DELAY_RANGE[0]:g} and {DELAY_RANGE[1]:g} (the torques "
                                f"logged that long after their positions), or None to estimate it; got {delay!r}",
                                argument="delay")
    return float(delay)


def _criterion(phi: np.ndarray, moving: np.ndarray, torque_rms: np.ndarray) -> Callable[[np.ndarray], float]:
    """The weighted residual of a fit of torques y (N, 3) on phi (N, 3, P) over the equations
    ``moving``: the sum over the joints of the residual's mean square over their torque's
    (torque_rms, N m), after the least-squares fit with those fixed weights (a projection,
    factored once: the regressor does not depend on the lag)."""
    weight = 1.0 / np.maximum(torque_rms, 1e-300)
    mask = moving * weight
    counts = np.maximum(moving.sum(axis=0), 1)
    q = np.linalg.qr((phi * mask[..., None]).reshape(-1, phi.shape[-1]))[0]

    def weighted(y: np.ndarray) -> float:
        yw = (y * mask).reshape(-1)
        r = (yw - q @ (q.T @ yw)).reshape(y.shape)
        return float(((r**2).sum(axis=0) / counts).sum())
    return weighted


def _estimate_lag(samples: Samples, tau0: np.ndarray, weighted: Callable[[np.ndarray], float],
                  hold: float) -> float:
    """The delay (s) in DELAY_BRACKET whose shifted torques minimise ``weighted`` (grid, then a
    parabola through the best three points), the timing's ``hold`` (samples) added to the lag."""
    assert samples.filtered_tau is not None and samples.index is not None
    grid = np.arange(DELAY_BRACKET[0], DELAY_BRACKET[1] + GRID_STEP / 2, GRID_STEP)
    values = np.array([weighted(lagged(samples.filtered_tau, samples.rate, samples.index, hold / samples.rate - d)
                                - tau0) for d in grid])
    k = int(np.clip(np.argmin(values), 1, len(grid) - 2))
    left, middle, right = values[k - 1:k + 2]
    curvature = left - 2 * middle + right
    step = 0.5 * (left - right) / curvature if curvature > 0 else 0.0
    return float(grid[k] + np.clip(step, -1.0, 1.0) * GRID_STEP)


def filtered(log: Log, cutoff: float, law: Friction, timing: str = "held", delay: float = 0.0,
             min_speed: float = MIN_SPEED) -> Samples:
    """The log filtered at ``cutoff`` (Hz), with the friction columns of ``law`` (Friction.torque
    with unit coefficients), edges cut, decimated (module doc, step 1); ``timing`` (TIMINGS);
    ``delay`` (s): the torques were logged that long after the positions they belong to, so
    the torque of the positions at t_k is read at t_k + delay (then the hold's half sample)."""
    rate = log.rate
    if not 0 < cutoff * RATE_PER_CUTOFF <= rate:
        raise LogError(f"{cutoff:g} Hz needs a log at {RATE_PER_CUTOFF * cutoff:g} Hz or faster "
                       f"(this one: {rate:.4g} Hz; central differences need {RATE_PER_CUTOFF:g} samples per "
                       "second per hertz of cutoff); lower --cutoff or log faster", argument="cutoff")
    # imported here: scipy.signal and scipy.ndimage take 0.4 s, which every command line start paid
    import scipy.ndimage
    import scipy.signal

    sos = scipy.signal.butter(FILTER_ORDER, cutoff, fs=rate, output="sos")
    theta = scipy.signal.sosfiltfilt(sos, log.theta, axis=0)
    tau = scipy.signal.sosfiltfilt(sos, log.tau, axis=0)
    smooth = tau
    if timing == "held":
        # the torque logged at t_k acts until t_k+1 (zero-order hold): low-passed, it is the
        # smooth signal half a period late; read it at t_k - 1/(2 rate), halfway back (without
        # this, viscous friction came out up to 20 % low)
        tau = np.concatenate([tau[:1], 0.5 * (tau[1:] + tau[:-1])])
    dt = 1.0 / rate
    dtheta = np.gradient(theta, dt, axis=0)
    ddtheta = np.gradient(dtheta, dt, axis=0)
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


def lagged(smooth: np.ndarray, rate: float, index: np.ndarray, lag: float) -> np.ndarray:
    """The filtered torques ``smooth`` (N, 3; N m, at ``rate`` Hz) read ``lag`` seconds before
    the samples ``index``, by linear interpolation (the torques are low-passed far below the
    rate: at a 20 Hz cutoff and 1 kHz, interpolation errs by 0.2 % of the cutoff's component)."""
    at = index - lag * rate
    low = np.clip(np.floor(at).astype(int), 0, len(smooth) - 2)
    share = np.clip(at - low, 0.0, 1.0)[:, None]
    return (1 - share) * smooth[low] + share * smooth[low + 1]


def _fit(phi: np.ndarray, y: np.ndarray, moving: np.ndarray | None = None,
         prior: tuple[np.ndarray, np.ndarray] | None = None) -> tuple[np.ndarray, ...]:
    """Weighted least squares of y (N, 3) on phi (N, 3, P) over the equations ``moving`` (N, 3)
    (all by default): (beta, covariance, residual (N, 3; 0 where not fitted), joint weights
    (3,), the log's information Phi_w^T Phi_w / s^2, the log alone's beta), each joint weighted
    by 1 / its residual standard deviation. With ``prior`` (beta_0, P), the Gauss-Markov estimate
    with that prior (module doc, step 2; prior.py), solved in the base parameters scaled by the
    prior's standard deviations (a singular value decomposition: the log alone may leave
    directions unconstrained)."""
    p = phi.shape[-1]
    moving = np.ones(y.shape, bool) if moving is None else moving
    phi, y = phi * moving[..., None], y * moving
    stacked = phi.reshape(-1, p)
    beta = np.linalg.lstsq(stacked, y.reshape(-1), rcond=None)[0]
    residual = y - phi @ beta
    joint_sigma = np.sqrt((residual**2).sum(axis=0) / np.maximum(moving.sum(axis=0) - p / 3, 1))
    weight = 1.0 / np.maximum(joint_sigma, 1e-300)
    weighted, yw = (phi * weight[:, None]).reshape(-1, p), (y * weight).reshape(-1)
    beta = log_beta = np.linalg.lstsq(weighted, yw, rcond=None)[0]
    rw = yw - weighted @ beta
    variance = rw @ rw / (moving.sum() - p)
    information = weighted.T @ weighted / variance
    if prior is None:
        covariance = inverse_information(information)
    else:
        beta0, spread = prior
        d = np.sqrt(np.diag(spread))                         # the prior's standard deviations
        root = np.linalg.cholesky(spread / np.outer(d, d))   # of the scaled prior's correlation
        inverse = scipy.linalg.solve_triangular(root, np.eye(p), lower=True)
        stacked = np.vstack([weighted * d / np.sqrt(variance), inverse])
        rhs = np.concatenate([yw / np.sqrt(variance), inverse @ (beta0 / d)])
        u, sizes, vt = np.linalg.svd(stacked, full_matrices=False)
        beta = d * (vt.T @ ((u.T @ rhs) / sizes))
        covariance = (vt.T / sizes**2) @ vt * np.outer(d, d)
    return beta, covariance, y - phi @ beta, weight, information, log_beta


def inverse_information(information: np.ndarray) -> np.ndarray:
    """The covariance of an information matrix (P, P), inf on the diagonal where it leaves a
    direction unconstrained (scaled to a unit diagonal first: the units span 1e-12)."""
    d = np.sqrt(np.maximum(np.diag(information), 1e-300))
    values, vectors = np.linalg.eigh(information / np.outer(d, d))
    if values.min() > 1e-13 * values.max():
        return np.linalg.inv(information / np.outer(d, d)) / np.outer(d, d)
    covariance = (vectors / np.maximum(values, 1e-300)) @ vectors.T / np.outer(d, d)
    unconstrained = (vectors[:, values <= 1e-13 * values.max()] ** 2).sum(axis=1) > 1e-6
    covariance[unconstrained, unconstrained] = np.inf
    return covariance


def _rms(residual: np.ndarray, moving: np.ndarray | None = None) -> np.ndarray:
    """RMS per joint (N, 3) -> (3,) over the equations ``moving`` (all by default)."""
    moving = np.ones(residual.shape, bool) if moving is None else moving
    return np.sqrt((residual**2 * moving).sum(axis=0) / np.maximum(moving.sum(axis=0), 1))


#: Angles further than this beyond the stops (rad) are no posture of the arm: refused before
#: the fit, as simulate refuses such a start.
NO_POSTURE = 2 * np.pi
#: Torques above this (N m) are no joint torque of a desk-top haptic arm (the Premium 1.5's
#: peak is 1.7 N m): refused before the fit (1e300 overflowed its arithmetic).
MAX_TORQUE = 1e3


def estimate(log: Log, phantom: Phantom, cutoff: float = 20.0, structure: str = "general",  # noqa: C901 (checks, then stages)
             prior_weight: float = 1e-3, progress: Callable[[float], None] | None = None,
             timing: str = "held", prior_spread: float = priors.SPREAD, delay: float | None = 0.0,
             gains: bool = True, min_speed: float = MIN_SPEED) -> Fit:
    """Identify the device of ``log`` on the configuration of ``phantom`` (its parameters are
    the prior, its friction law the friction columns): the base parameters of ``structure``
    ("general": the rigid body in full; "report": the report's structure, for a model in the
    report's form) and the nearest physically consistent parameters (module doc). Raises
    LogError for a log that cannot be identified at all (too short, too low a rate for
    ``cutoff`` Hz, constant torques; with ``prior_spread`` inf, a direction the log alone leaves
    unconstrained); ``Fit.problems`` lists the reasons a fitted result should not be written.
    ``timing``: how the torques relate to the times
    (TIMINGS: "held" commands, the default, or "sampled" values). ``prior_spread``: the prior's
    relative standard deviation of every physical parameter (prior.py; inf: the log alone).
    ``delay`` (s): how long after the positions they belong to the torques were logged (the
    torque of the positions at t is read at t + delay), or None to estimate it: the delay in
    DELAY_BRACKET whose shifted torques leave the smallest weighted residual (_criterion). The
    regressor does not depend on the delay, only the torques do; a wrong delay leaves about
    (delay error) x dtau/dt in them, whose jerk-driven part no column of the regressor holds, so
    the residual grows with the error on either side and its minimum is the true delay.
    Both timings are also fitted (at zero delay when it is estimated, else at the given one):
    ``Fit.timing_residual``, ``Fit.timing_lines``, ``Fit.timing_warning``. ``gains``: estimate each
    joint's torque gain relative to joint 1 (module doc, step 2; ``Fit.gains``), or take the
    log's torques as they are (False). ``min_speed`` (rad/s): a joint's equation is fitted where
    its rate stays above it over the filter's span (MIN_SPEED).
    ``progress(share)`` is called as stages end."""
    def stage(share: float) -> None:
        if progress is not None:
            progress(share)

    if not isinstance(log, Log):
        raise InvalidInputError(f"expected a phantom_pin.identification.Log (read_log), got {log!r}", argument="log")
    if not isinstance(phantom, Phantom):
        raise InvalidInputError(f"expected a phantom_pin.Phantom, got {phantom!r}", argument="phantom")
    for name, value in (("cutoff", cutoff), ("prior_weight", prior_weight), ("min_speed", min_speed)):
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not np.isfinite(value) or value <= 0:
            raise InvalidInputError(f"expected a finite number > 0, got {value!r}", argument=name)
    spread = priors.spread_argument(prior_spread)
    delay = delay_argument(delay)
    if progress is not None and not callable(progress):
        raise InvalidInputError(f"expected a callable (share) or None, got {progress!r}", argument="progress")
    duration = float(log.t[-1] - log.t[0])
    if cutoff * duration < MIN_CYCLES:
        raise LogError(f"{cutoff:g} Hz is too low for a {duration:.3g} s log (the filter needs at least "
                       f"{MIN_CYCLES:g} of its periods in the log: {MIN_CYCLES / duration:.3g} Hz or more)",
                       argument="cutoff")
    if not isinstance(gains, bool):
        raise InvalidInputError(f"expected True (estimate the joints' relative torque gains) or False, got {gains!r}",
                                argument="gains")
    if timing not in TIMINGS:
        raise InvalidInputError(f"expected one of {', '.join(TIMINGS)}, got {timing!r}", argument="timing")
    if structure not in STRUCTURES:
        raise InvalidInputError(f"expected one of {', '.join(STRUCTURES)}, got {structure!r}", argument="structure")
    beyond = np.abs(phantom.config.limits.stops.penetration(log.theta)).max(axis=0)
    if (beyond > NO_POSTURE).any():  # before any arithmetic on them (1e300 rad: no SVD converges)
        j = int(np.argmax(beyond))
        raise LogError(f"theta{j + 1}: the log's angles reach {beyond[j]:.3g} rad beyond the stops, more than a "
                       "turn: no posture of the arm; are they in degrees? (the log holds the report's theta in rad, "
                       "or use --convention openhaptics)")
    huge = np.abs(log.tau).max(axis=0)
    if (huge > MAX_TORQUE).any():
        j = int(np.argmax(huge))
        raise LogError(f"tau{j + 1}: the log's torques reach {huge[j]:.3g} N m, more than {MAX_TORQUE:g} N m: not "
                       "joint torques in N m (mN m? use --convention openhaptics for OpenHaptics' joint torques)")
    constant = [f"tau{j + 1}" for j in range(3) if np.ptp(log.tau[:, j]) == 0]
    if constant:
        raise LogError(f"{', '.join(constant)}: constant torque{'s' if len(constant) > 1 else ''} over the whole "
                       "log: nothing to identify (the log must hold the torques commanded during the motion)")
    model = STRUCTURES[structure](phantom)
    samples = filtered(log, cutoff, phantom.config.actuation.friction, timing, 0.0 if delay is None else delay,
                       min_speed)
    stage(0.1)
    if len(samples.theta) < 50:
        raise LogError(f"too short: {len(samples.theta)} samples after filtering at {cutoff:g} Hz and cutting "
                       f"{EDGE} s at each end (need 50)")
    phi, tau0 = model.regressor_of(samples.theta, samples.dtheta, samples.ddtheta, samples.friction)
    stage(0.4)
    moving = samples.moving                  # the equations fitted: joints clear of rest
    if (moving.sum(axis=0) < 50).any():
        still = ", ".join(str(j + 1) for j in np.flatnonzero(moving.sum(axis=0) < 50))
        raise LogError(f"too little motion: joint(s) {still} move faster than {min_speed:g} rad/s in fewer than 50 "
                       f"samples filtered at {cutoff:g} Hz; log an excitation trajectory (phantom-pin excite), "
                       "filter less, or lower --min-speed")
    smooth, index = samples.filtered_tau, samples.index
    assert smooth is not None and index is not None
    weighted = _criterion(phi, moving, _rms(smooth[index] - tau0, moving))    # the same for any timing
    estimated = delay is None
    at = delay = 0.0 if delay is None else delay
    phi = phi * moving[..., None]
    stacked = phi.reshape(-1, phi.shape[-1])
    norms = np.linalg.norm(stacked, axis=0)
    condition = float(np.linalg.cond(stacked / np.where(norms > 0, norms, 1.0)))     # a diagnostic
    beta0, spread_covariance = priors.base_prior(model.matrix, model.offset, model.prior, model.scale,
                                                 spread if np.isfinite(spread) else 1.0)
    p = phi.shape[-1]
    prior = (beta0, spread_covariance) if np.isfinite(spread) else None

    def lag(scale: np.ndarray) -> tuple[float, Samples]:
        """The delay estimated on the torques times ``scale`` (joint 1's scale), and the samples at it."""
        found = _estimate_lag(dataclasses.replace(samples, filtered_tau=smooth * scale), tau0, weighted, HOLD[timing])
        return found, dataclasses.replace(samples, tau=lagged(smooth, samples.rate, index,
                                                             HOLD[timing] / samples.rate - found))

    if estimated:
        delay, samples = lag(np.ones(3))
    solved = _solve_gains(phi, samples.tau, tau0, moving, prior, (1, 2) if gains else ())
    estimated_gains = solved[-1]
    if gains:            # correct only the gains the log shows to differ from 1 (module doc, step 2)
        shown = tuple(j for j in (1, 2) if abs(estimated_gains[0][j] - 1) >
                      max(GAIN_NOTED, GAIN_EVIDENCE * estimated_gains[1][j]))
        if estimated and shown:          # the delay again with the gains corrected: a joint's scale moves it
            scale = np.ones(3)
            scale[list(shown)] = estimated_gains[0][list(shown)]
            delay, samples = lag(scale)
            solved = _solve_gains(phi, samples.tau, tau0, moving, prior, (1, 2))
            estimated_gains = solved[-1]
        if shown != (1, 2):
            solved = _solve_gains(phi, samples.tau, tau0, moving, prior, shown)
    beta, covariance, information, log_beta, log_rms, (gain, _) = solved
    log_sigma = np.sqrt(np.diag(inverse_information(information)))[:p]
    if information.shape[0] > p:      # beta's marginal: its covariance block, the information's Schur complement
        information = information[:p, :p] - information[:p, p:] @ np.linalg.solve(information[p:, p:],
                                                                                 information[p:, :p])
    covariance, log_beta = covariance[:p, :p], log_beta[:p]
    timing_residual = {name: weighted(lagged(smooth * gain, samples.rate, index, HOLD[name] / samples.rate - at)
                                      - tau0) for name in TIMINGS}     # in joint 1's scale, the gains applied
    logged = (samples.tau - tau0) * moving
    samples = dataclasses.replace(samples, tau=samples.tau * gain)     # in joint 1's torque scale
    y = (samples.tau - tau0) * moving
    residual = y - phi @ beta
    sigma = np.sqrt(np.diag(covariance))
    if not np.isfinite(sigma).all():
        loose = ", ".join(model.base_names[k].split(" = ")[0][:40] for k in np.flatnonzero(~np.isfinite(sigma))[:3])
        raise LogError(f"not exciting enough for the log alone: it leaves {loose} unconstrained; identify with "
                       "the prior (a finite prior_spread)", argument="prior_spread")
    correlation = covariance / np.outer(sigma, sigma)
    values, vectors = np.linalg.eigh(correlation)      # root^T root = covariance^-1 (no Cholesky: it
    root = (vectors / np.sqrt(np.maximum(values, 1e-300))).T / sigma   # may be singular to rounding)
    stage(0.5)
    x = model.nearest(beta, root, prior_weight)
    written = model.matrix @ x + model.offset
    stage(0.7)
    comparison = _comparison(model, phantom, samples)
    fit = Fit(model.name, model.base_names, model.units, beta, sigma, _rms(residual, moving),
              _rms(y - phi @ written, moving), _rms(y, moving), condition, len(samples.theta), x, written,
              model.overrides(x), comparison, gain, estimated_gains, (), beta0, log_beta, log_sigma, log_rms,
              judge(model.regressor_of, phantom.config.limits, phi, y, moving, written, covariance, beta0,
                    information, priors.typical(model.matrix, model.scale), model.base_names, spread),
              delay, estimated, timing, timing_residual, phantom.config.actuation.ratios)
    problems = _problems(fit, model, phi, logged, log, phantom)
    stage(1.0)
    return dataclasses.replace(fit, problems=tuple(problems))


def _solve_gains(phi: np.ndarray, tau: np.ndarray, tau0: np.ndarray, moving: np.ndarray,
                 prior: tuple[np.ndarray, np.ndarray] | None, free: tuple[int, ...]) -> tuple:
    """The estimate of beta with the torque gains of the joints ``free`` (of 1, 2; the others
    1): tau_j = (Phi_j beta + tau0_j) / g_j (module doc, step 2) solved by Gauss-Newton in beta
    and the inverse gains, linear about the last estimate, the inverse gains' columns being the
    model's torques: free of the log's noise (its own torques there would let a smaller inverse
    gain shrink the residual, biasing the gains). ``phi`` (N, 3, P) and ``tau``, ``tau0`` (N, 3;
    N m) the regressor, the logged and the known torques, ``prior`` (beta_0, P) or None. Returns
    (beta, covariance, information (of beta and the free inverse gains), the log alone's beta
    and residual RMS per joint in joint 1's scale (N m), (gains (3,), standard deviations (3,)))."""
    p, scale = phi.shape[-1], np.ones(3)
    # where to start: the gains at 1 (with none free, the loop's one pass is that fit: not done twice)
    beta = _fit(phi, (tau - tau0) * moving, moving, prior)[0] if free else np.zeros(p)
    if prior is not None:
        prior = (np.concatenate([prior[0], np.zeros(len(free))]),
                 scipy.linalg.block_diag(prior[1], GAIN_SPREAD**2 * np.eye(len(free))))
    for _ in range(GAIN_ITERATIONS):
        predicted = (phi @ beta + tau0) * moving
        columns = np.zeros((*tau.shape, len(free)))
        for k, j in enumerate(free):
            columns[:, j, k] = predicted[:, j]
        system = np.concatenate([phi * scale[:, None], columns], axis=-1)
        rhs = (tau - scale * tau0) * moving
        if prior is not None:         # the inverse gains' prior mean is 1: their change's, 1 - scale
            prior = (np.concatenate([prior[0][:p], 1.0 - scale[list(free)]]), prior[1])
        solution, covariance, _, _, information, log_beta = _fit(system, rhs, moving, prior)
        beta, change = solution[:p], solution[p:]
        scale[list(free)] += change
        if not free or np.abs(change).max() <= GAIN_TOLERANCE:
            break
    log_rms = _rms(rhs - system @ log_beta, moving) / scale
    sigma = np.zeros(3)
    sigma[list(free)] = np.sqrt(np.diag(covariance)[p:]) / scale[list(free)] ** 2
    return beta, covariance, information, log_beta, log_rms, (1.0 / scale, sigma)


def _comparison(model: Structure, phantom: Phantom, samples: Samples) -> tuple[str, np.ndarray] | None:
    """The other structure's least-squares residual RMS per joint (N m), if it applies."""
    other = "report" if model.name == "general" else "general"
    if other == "report" and phantom.config.report is None:
        return None
    phi, tau0 = STRUCTURES[other](phantom).regressor_of(samples.theta, samples.dtheta, samples.ddtheta,
                                                        samples.friction)
    y = samples.tau - tau0
    return other, _rms(_fit(phi, y, samples.moving)[2], samples.moving)


def _problems(fit: Fit, model: Structure, phi: np.ndarray, y: np.ndarray, log: Log, phantom: Phantom) -> list[str]:
    """Why ``fit`` should not be written (module doc, step 4), most telling first; ``y`` the
    logged torques less the known ones (N m, before the gains' correction)."""
    problems = []
    worse = fit.prediction.worse()
    if worse is not None:
        problems.append(worse)
    beyond = float(np.abs(phantom.config.limits.stops.penetration(log.theta)).max())
    if beyond > BEYOND_STOPS:
        problems.append(f"theta: the log's angles reach {beyond:.3g} rad beyond the stops; are they in degrees, or "
                        "in another convention? (the log holds the report's theta in rad, or use --convention "
                        "openhaptics)")
    share = fit.log_rms / fit.torque_rms      # the log alone's: the prior may pull a wrong log's fit
    if share.max() > MAX_RESIDUAL_SHARE:
        problems.append("the fit leaves " + ", ".join(f"{100 * s:.0f} %" for s in share) + " of the torque RMS "
                        f"(at most {100 * MAX_RESIDUAL_SHARE:.0f} %): the torques do not follow the motion; check "
                        "that theta and tau are the same samples, in rad and N m")
    prior = phi @ (model.matrix @ model.prior + model.offset)
    sizes = (y * prior).sum(axis=0) / np.maximum((prior * prior).sum(axis=0), 1e-300)    # per joint
    wrong = [j for j in range(3) if not TORQUE_SCALE[0] <= sizes[j] <= TORQUE_SCALE[1]]
    if len(wrong) == 3:
        size = float((y * prior).sum() / (prior * prior).sum())
        problems.append(f"tau: the logged torques are {size:.3g} times the model's prediction along the motion"
                        + ("; are their signs flipped (amplifier polarity)?" if size < 0 else
                           "; are they in another unit (N m at the joint, not mN m or motor torques)?"))
    follows = share.max() <= MAX_RESIDUAL_SHARE        # else the torques' sizes say nothing per joint
    for j in wrong if len(wrong) < 3 and follows else ():
        problems.insert(0, f"tau{j + 1}: the logged torques are {sizes[j]:.3g} times the model's prediction along "
                        "the motion" + (f": tau{j + 1}'s sign is flipped (amplifier polarity)?" if sizes[j] < 0 else
                                        "; in another unit, or converted with another joint's transmission ratio? The "
                                        "log must hold joint torques (N m at the joint: motor torque x ratio)"))
    values, sigma = fit.friction
    negative = [name for name, v, s in zip(model.names[-6:], values, sigma) if v < -3 * s]
    if negative:
        problems.append(f"negative friction ({', '.join(negative)}): check the torque signs, units and "
                        "transmission ratios (friction is written as 0 or more)")
    moved = np.abs(fit.written - fit.beta)
    far = np.flatnonzero((moved > MAX_SHIFT_SIGMA * fit.sigma) & (moved > SHIFT_SHARE * np.abs(fit.beta)))
    if far.size:
        k = far[np.argmax((moved / fit.sigma)[far])]
        flipped = np.sign(fit.written[k]) != np.sign(fit.beta[k])
        name = model.base_names[k].split(" = ")[0]
        name = name if len(name) <= 40 else name[:40].rsplit(" ", 1)[0] + " ..."
        problems.append(f"the nearest physical parameters move beta{k + 1} ({name}) from "
                        f"{fit.beta[k]:.4g} to {fit.written[k]:.4g} {fit.units[k]} ({moved[k] / fit.sigma[k]:.3g} "
                        f"standard deviations{', a flipped sign' if flipped else ''}): the estimate is not of a "
                        "physical arm; check torque signs, units and transmission ratios")
    for j in (1, 2) if len(wrong) < 3 and follows else ():    # the gains of joints whose size is plausible
        if j in wrong or GAIN_BOUNDS[0] <= fit.gains[j] <= GAIN_BOUNDS[1]:
            continue
        problems.insert(0, f"tau{j + 1} is {1 / fit.gains[j]:.3g} times joint 1's torque scale (gain "
                        f"{fit.gains[j]:.3g}" + (f"): tau{j + 1}'s sign is flipped (amplifier polarity)" if
                                                 fit.gains[j] < 0 else
                                                 f", outside {GAIN_BOUNDS[0]:g}-{GAIN_BOUNDS[1]:g}: no drive's "
                                                 "tolerance): converted with another joint's transmission ratio or "
                                                 "unit? The log must hold joint torques (N m at the joint)"))
    return problems
