"""The estimate of a device's parameters from its log, in named stages (docs/identification.md):

1. the cheap refusals (checks.py): the arguments, a log no arithmetic should touch, the filtered
   log's length and motion, the torques' size and sign against the prior's prediction; the
   friction speed threshold and the torque timing, where not given, chosen on held-out
   quarters of the log (selection.py);
2. timing (timing.py): the delay between positions and torques, estimated (where the angles are
   noisy, on the log filtered at a lower cutoff: filtering.quiet_cutoff) or given; for a
   closed-loop log with its reference, every stage from here uses instrumental variables
   (instruments.py: the torque noise the loop feeds back into the motion biases least squares);
3. gains (least_squares.solve_gains): each joint's torque gain relative to joint 1, corrected
   where the log shows it differs from 1 (by more than GAIN_NOTED and GAIN_EVIDENCE standard
   deviations) and the correction predicts held-out quarters of the log better
   (selection.validate_gains), and the delay estimated again with the corrected ones;
4. the fit with the prior (least_squares.fit): the base parameters and their covariance;
5. the physical projection (physical.nearest): the structure's parameters whose base
   parameters are nearest to beta in the covariance's metric, every link physical, friction >= 0;
6. the prediction (prediction.judge): the torque uncertainty of the written parameters;
7. the verdict (checks.problems): why the result should not be written, one line each.
The words a user reads about a Fit are in result.py, the module that prints them.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

import numpy as np

from phantom_pin.dynamics.phantom import Phantom
from phantom_pin.exceptions import InvalidInputError, LogError
from phantom_pin.identification.data.io import Log
from phantom_pin.identification.data.timing import HOLD, TIMINGS, criterion, delay_argument, estimate_delay
from phantom_pin.identification.fitting import checks
from phantom_pin.identification.fitting.filtering import CUTOFF, MIN_CYCLES, MIN_SPEED, Samples, filtered, quiet_cutoff
from phantom_pin.identification.fitting.fit import Curves, Fit
from phantom_pin.identification.fitting.instruments import (
    Instruments,
    instrumented_delay,
    instruments,
    reference_angles,
)
from phantom_pin.identification.fitting.least_squares import (
    condition_number,
    inverse_information,
    marginal,
    metric_root,
    rms,
    solve_gains,
)
from phantom_pin.identification.fitting.least_squares import fit as least_squares
from phantom_pin.identification.fitting.prediction import judge
from phantom_pin.identification.fitting.selection import FOLDS, choose_min_speed, choose_timing, validate_gains
from phantom_pin.identification.structure import prior as priors
from phantom_pin.identification.structure.structures import STRUCTURES, Structure

#: A gain is corrected (and the driver told) where the log shows it differs from 1: by more than
#: GAIN_NOTED and GAIN_EVIDENCE standard deviations; else it stays 1 and the estimate is only
#: reported. Both bounds, because in a closed loop the torque noise moves the joints it drives,
#: which biases the estimate beyond its standard deviation: measured -0.5 to -0.9 % on 60 s
#: sum-of-sines logs with 1 % torque noise (1-1.7 sigma), up to 3.5 sigma on excite's 10 s
#: trajectory with 2 mN m, and -0.45 to -0.57 % (4-5 sigma) on excite's 20 s trajectory with 10 mA
#: of current noise; correcting such a gain cost 0.3-0.9 % of held-out accuracy where the drives
#: were right. A torque constant 2 % off or a ratio misread (3.5 %) is well beyond both.
GAIN_NOTED, GAIN_EVIDENCE = 0.01, 4.0
#: A gain that passes both is corrected only where that makes the held-out prediction better on
#: every one of the log's FOLDS quarters (selection.validate_gains: estimated on three, judged on
#: the fourth, against the fit with the gains at 1). Not a size: a real gain error's improvement
#: is as small as the rest of the residual is large (a 2 % torque constant on a lab's sum of
#: sines with 1 % torque noise: 0.3-1.0 % per quarter, every quarter), while a gain the closed
#: loop's noise biased improves some quarters and worsens others (the CAD's lab log with 10 mA:
#: -0.2 to +0.2 %, which corrected joint 3 to 0.935, and the held-out error with it).
#: The report's structure needs the general model when it leaves more than this times the
#: general model's residual on some joint.
NEEDS_GENERAL = 1.2


@dataclasses.dataclass(frozen=True)
class _Regression:
    """A log made ready for the fit: its filtered ``samples``, its ``structure``, the
    regressor ``phi`` (N, 3, P) zeroed outside the fitted equations ``moving`` (N, 3), the known
    torques ``tau0`` (N, 3; N m), the prior (beta_0, P) or None (prior_spread inf), the friction
    speed threshold ``min_speed`` (rad/s) and, where it was chosen, each one's held-out residual;
    the torque ``timing`` the samples' torques are read at and, where it was chosen, each
    timing's held-out residual (selection.choose_timing)."""

    samples: Samples
    structure: Structure
    phi: np.ndarray
    tau0: np.ndarray
    moving: np.ndarray
    beta0: np.ndarray
    prior: tuple[np.ndarray, np.ndarray] | None
    min_speed: float = MIN_SPEED
    min_speed_scores: dict[float, float] = dataclasses.field(default_factory=dict)
    instruments: Instruments | None = None
    timing: str = "held"
    timing_scores: dict[str, float] = dataclasses.field(default_factory=dict)

    @property
    def solved(self) -> np.ndarray:
        """The regressor the fits solve with: ``phi``, or its projection on the instruments."""
        if self.instruments is None:
            return self.phi
        return self.instruments.projected(self.phi, self.moving)


@dataclasses.dataclass(frozen=True)
class _Timed:
    """Stages 2-4's result: the ``samples`` with the torques at the ``delay`` (s), the estimate
    with the prior (``beta``, ``covariance``, ``information`` of beta and the free inverse gains,
    the log alone's ``log_beta`` and ``log_rms`` (N m)), the ``gains`` applied and those
    ``estimated`` ((3,), (3,): least_squares.solve_gains), each timing's weighted ``residuals``,
    and where a gain passed the evidence rule, the held-out ``gain_scores`` of keeping the gains
    at 1 and of correcting them and the quarters where correcting was better
    (selection.validate_gains), else empty."""

    samples: Samples
    delay: float
    beta: np.ndarray
    covariance: np.ndarray
    information: np.ndarray
    log_beta: np.ndarray
    log_rms: np.ndarray
    gains: np.ndarray
    estimated: tuple[np.ndarray, np.ndarray]
    residuals: dict[str, float]
    gain_scores: dict[str, float]


def estimate(log: Log, phantom: Phantom, cutoff: float = CUTOFF, structure: str = "general",
             prior_weight: float = 1e-3, progress: Callable[[float], None] | None = None,
             timing: str | None = "held", prior_spread: float = priors.SPREAD, delay: float | None = 0.0,
             gains: bool = True, min_speed: float | None = MIN_SPEED, refuse: bool = False,
             reference: tuple[np.ndarray, np.ndarray] | None = None) -> Fit:
    """Identify the device of ``log`` on the configuration of ``phantom`` (its parameters are
    the prior, its friction law the friction columns): the base parameters of ``structure``
    ("general": the rigid body in full; "report": the report's structure, for a model in the
    report's form) and the nearest physically consistent parameters, in the stages of the
    module doc. ``cutoff`` (Hz): the filter's (filtering.py). ``timing``: how the torques
    relate to the times (timing.TIMINGS: "held" commands, the default, or "sampled" values), or
    None: chosen from the log on held-out parts of it (selection.choose_timing;
    ``Fit.timing_scores``); both timings are also fitted (``Fit.timing_residual``). ``prior_spread``: the prior's
    relative standard deviation of every physical parameter (prior.py; inf: the log alone).
    ``delay`` (s): how long after the positions they belong to the torques were logged, or
    None to estimate it (timing.py; where the angles are noisy, on the log filtered at a lower
    cutoff: filtering.quiet_cutoff, ``Fit.delay_cutoff``). ``gains``: estimate each joint's torque gain relative to
    joint 1 (``Fit.gains``), or take the log's torques as they are (False). ``min_speed``
    (rad/s): a joint's equation is fitted where its rate stays above it (filtering.MIN_SPEED);
    None: chosen from the log on held-out parts of it (selection.py; ``Fit.min_speed``).
    ``refuse``: raise LogError at the problems found before any fit (checks.before_fit: the
    torques' unit or a joint's sign) instead of fitting and listing them in ``Fit.problems``.
    ``reference``: (t s, theta (M, 3) rad) the motion the log's servo loop tracked, read from the
    log's start (excite's trajectory: io.read_trajectory's first two): the log is a closed loop
    on it, and the estimate uses instrumental variables (instruments.py; ``Fit.closed_loop``) and
    keeps the torque gains at 1 (``gains`` is then not used: instrumented, they are biased);
    InvalidInputError, or LogError where the log does not follow it.
    ``progress(share)`` is called as stages end.

    Raises InvalidInputError naming a bad argument; LogError for a log that cannot be
    identified at all (too short, too low a rate for ``cutoff``, constant torques, too little
    motion; with ``prior_spread`` inf, a direction the log alone leaves unconstrained)."""
    spread, delay = _arguments(log, phantom, cutoff, structure, prior_weight, progress, timing, prior_spread,
                               delay, gains, min_speed)

    def stage(share: float) -> None:
        if progress is not None:
            progress(share)

    angles = None if reference is None else reference_angles(log, reference)
    # instrumented, the gains are biased (joint 2: 1.185 for a true 1.02; docs/identification.md): kept at 1
    gains = gains and angles is None
    checks.refuse_log(log, phantom)
    ready = _regression(log, phantom, cutoff, structure, timing, spread, 0.0 if delay is None else delay,
                        min_speed, refuse)
    timing = ready.timing                   # given, or chosen from the log
    if angles is not None:
        ready = dataclasses.replace(ready, instruments=instruments(
            log, angles, ready.structure, cutoff, ready.samples, phantom.config.actuation.friction, timing))
    quiet = _quiet(log, phantom, ready, cutoff, delay, timing)
    stage(0.4)
    timed = _timing_and_gains(ready, timing, delay, gains, quiet[2])
    stage(0.5)
    chosen, phi, moving, p = ready.structure, ready.phi, ready.moving, ready.phi.shape[-1]
    log_sigma = np.sqrt(np.diag(inverse_information(timed.information)))[:p]
    covariance, information = timed.covariance[:p, :p], marginal(timed.information, p)
    x, sigma = _projection(ready, timed.beta, covariance, prior_weight)
    stage(0.7)
    samples = dataclasses.replace(timed.samples, tau=timed.samples.tau * timed.gains)   # in joint 1's torque scale
    y = (samples.tau - ready.tau0) * moving
    written = chosen.matrix @ x + chosen.offset
    fit = Fit(structure=chosen.name, names=chosen.base_names, units=chosen.units, beta=timed.beta, sigma=sigma,
              rms=rms(y - phi @ timed.beta, moving), written_rms=rms(y - phi @ written, moving),
              torque_rms=rms(y, moving), condition=condition_number(phi.reshape(-1, phi.shape[-1])),
              samples=len(samples.theta), x=x, written=written, overrides=chosen.overrides(x),
              comparison=_comparison(chosen, phantom, samples), gains=timed.gains, gains_estimated=timed.estimated,
              prior_beta=ready.beta0, log_beta=timed.log_beta[:p], log_sigma=log_sigma, log_rms=timed.log_rms,
              prediction=judge(chosen.regressor_of, phantom.config.limits, phi, y, moving, written, covariance,
                               ready.beta0, information, priors.typical(chosen.matrix, chosen.scale),
                               chosen.base_names, spread),
              delay=timed.delay, delay_estimated=delay is None, delay_cutoff=quiet[:2], timing=timing,
              timing_residual=timed.residuals, timing_scores=ready.timing_scores,
              ratios=phantom.config.actuation.ratios, min_speed=ready.min_speed,
              min_speed_scores=ready.min_speed_scores, gain_scores=timed.gain_scores,
              closed_loop="" if ready.instruments is None else ready.instruments.words(),
              curves=Curves(log.t[samples.index], samples.dtheta, samples.tau, phi @ written + ready.tau0,
                            samples.friction @ x[-6:], moving))
    problems = checks.problems(fit, chosen, phi, (timed.samples.tau - ready.tau0) * moving, log, phantom)
    stage(1.0)
    return dataclasses.replace(fit, problems=tuple(problems))


def _arguments(log: object, phantom: object, cutoff: object, structure: object, prior_weight: object,
               progress: object, timing: object, prior_spread: object, delay: object, gains: object,
               min_speed: object) -> tuple[float, float | None]:
    """estimate's arguments checked (InvalidInputError naming the one, LogError where the log's
    length does not suit ``cutoff``): the prior's spread and the delay (None: estimate it)."""
    if not isinstance(log, Log):
        raise InvalidInputError(f"expected a phantom_pin.identification.Log (read_log), got {log!r}", argument="log")
    if not isinstance(phantom, Phantom):
        raise InvalidInputError(f"expected a phantom_pin.Phantom, got {phantom!r}", argument="phantom")
    _check_positive(cutoff, prior_weight, min_speed)
    spread = priors.spread_argument(prior_spread)
    checked = delay_argument(delay)
    if progress is not None and not callable(progress):
        raise InvalidInputError(f"expected a callable (share) or None, got {progress!r}", argument="progress")
    duration = float(log.t[-1] - log.t[0])
    assert isinstance(cutoff, (int, float))
    if cutoff * duration < MIN_CYCLES:
        raise LogError(f"{cutoff:g} Hz is too low for a {duration:.3g} s log (the filter needs at least "
                       f"{MIN_CYCLES:g} of its periods in the log: {MIN_CYCLES / duration:.3g} Hz or more)",
                       argument="cutoff")
    if not isinstance(gains, bool):
        raise InvalidInputError(f"expected True (estimate the joints' relative torque gains) or False, got {gains!r}",
                                argument="gains")
    if timing is not None and timing not in TIMINGS:
        raise InvalidInputError(f"expected one of {', '.join(TIMINGS)}, or None to choose it from the log; got "
                                f"{timing!r}", argument="timing")
    if structure not in STRUCTURES:
        raise InvalidInputError(f"expected one of {', '.join(STRUCTURES)}, got {structure!r}", argument="structure")
    return spread, checked


def _check_positive(cutoff: object, prior_weight: object, min_speed: object) -> None:
    """estimate's numbers that must be finite and > 0 (``min_speed`` unless None): InvalidInputError
    naming the first that is not."""
    for name, value in (("cutoff", cutoff), ("prior_weight", prior_weight)) + (
            () if min_speed is None else (("min_speed", min_speed),)):
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not np.isfinite(value) or value <= 0:
            raise InvalidInputError(f"expected a finite number > 0, got {value!r}", argument=name)


def _regression(log: Log, phantom: Phantom, cutoff: float, structure: str, timing: str | None, spread: float,
                delay: float, min_speed: float | None, refuse: bool) -> _Regression:
    """Stage 1: the log filtered, the regressor, the prior, and the refusals that need no fit
    (with ``refuse``, the torques' size and sign as well); the timing chosen where None (after
    the threshold, chosen with the held timing: the timings differ by half a sample only)."""
    given_timing, timing = timing, timing or "held"
    model = STRUCTURES[structure](phantom)
    beta0, spread_covariance = priors.base_prior(model.matrix, model.offset, model.prior, model.scale,
                                                 spread if np.isfinite(spread) else 1.0)
    prior = (beta0, spread_covariance) if np.isfinite(spread) else None
    scores: dict[float, float] = {}
    if min_speed is None:          # each threshold's filtered log checked there, the chosen one's kept
        min_speed, scores, samples = choose_min_speed(log, phantom, model, cutoff, timing, delay, prior)
    else:
        samples = filtered(log, cutoff, phantom.config.actuation.friction, timing, delay, min_speed)
        checks.refuse_motion(samples.moving, cutoff, min_speed)
    phi, tau0 = model.regressor_of(samples.theta, samples.dtheta, samples.ddtheta, samples.friction)
    moving = samples.moving                  # the equations fitted: joints clear of rest
    phi = phi * moving[..., None]
    timing_scores: dict[str, float] = {}
    if given_timing is None:
        timing, timing_scores = choose_timing(samples, phi, tau0, delay, prior)
        samples = samples.at(HOLD[timing] / samples.rate - delay)
    if refuse:
        found = checks.before_fit((samples.tau - tau0) * moving, phi @ (model.matrix @ model.prior + model.offset))
        if found:
            raise checks.RefusedError(found)
    return _Regression(samples, model, phi, tau0, moving, beta0, prior, min_speed, scores, timing=timing,
                       timing_scores=timing_scores)


def _quiet(log: Log, phantom: Phantom, ready: _Regression, cutoff: float, delay: float | None, timing: str
           ) -> tuple[float, dict[float, float], tuple[Samples, np.ndarray, Callable[[np.ndarray], float]] | None]:
    """Where the delay is estimated from the residual (``delay`` None, no instruments: theirs is
    instrumented), the cutoff (Hz) the angles' noise allows below the fit's ``cutoff`` and each
    cutoff's noise share (filtering.quiet_cutoff), and where it is lower, the equations the delay
    is estimated on: the log filtered there at ``timing``, with the fit's threshold and structure
    (the samples, the known torques tau0 (N, 3; N m), the weighted residual: timing.criterion),
    unless they leave too little motion (checks.refuse_motion: then the fit's ``cutoff``, the
    shares and None); else (``cutoff``, {}, None)."""
    if delay is not None or ready.instruments is not None:
        return cutoff, {}, None
    quiet, shares = quiet_cutoff(log, cutoff)
    if quiet == cutoff:
        return cutoff, shares, None
    samples = filtered(log, quiet, phantom.config.actuation.friction, timing, 0.0, ready.min_speed)
    try:                      # the lower cutoff's longer span around rest leaves fewer equations
        checks.refuse_motion(samples.moving, quiet, ready.min_speed)
    except LogError:          # estimated at the fit's cutoff, and the delay line says why
        return cutoff, shares, None
    phi, tau0 = ready.structure.regressor_of(samples.theta, samples.dtheta, samples.ddtheta, samples.friction)
    return quiet, shares, (samples, tau0, _delay_criterion(samples, phi * samples.moving[..., None], tau0))


def _delay_criterion(samples: Samples, phi: np.ndarray, tau0: np.ndarray) -> Callable[[np.ndarray], float]:
    """The weighted residual the delay is estimated by (timing.criterion) on ``phi`` (N, 3, P),
    zeroed outside ``samples.moving``, each joint weighted by its filtered torque's RMS less
    ``tau0`` (N, 3; N m, the known torques) over the fitted equations (any timing)."""
    return criterion(phi, samples.moving, rms(samples.filtered_tau[samples.index] - tau0, samples.moving))


def _timing_and_gains(ready: _Regression, timing: str, delay: float | None, gains: bool,
                      quiet: tuple[Samples, np.ndarray, Callable[[np.ndarray], float]] | None = None) -> _Timed:
    """Stages 2-4: the delay (s; estimated when None, on the ``quiet`` equations where given:
    ``_quiet``) and the torque gains (corrected where the log shows them), then the fit with the
    prior; each timing's weighted residual."""
    samples, tau0, moving, measured, prior = ready.samples, ready.tau0, ready.moving, ready.phi, ready.prior
    phi = ready.solved                     # measured, or its projection on the instruments
    residuals_with = None if ready.instruments is None else measured       # least_squares.fit's measured
    weighted = _delay_criterion(samples, measured, tau0)

    def lag(scale: np.ndarray) -> tuple[float, Samples]:
        """The delay estimated on the torques times ``scale`` (joint 1's scale), and the samples at it."""
        if ready.instruments is None:
            on, known, residual = quiet or (samples, tau0, weighted)
            found = estimate_delay(on.filtered_tau * scale, on.rate, on.index, known, residual, HOLD[timing])
        else:
            found = instrumented_delay(ready.instruments, samples, measured, phi, tau0, moving, prior,
                                       HOLD[timing], scale)
        return found, samples.at(HOLD[timing] / samples.rate - found)

    at, used = (0.0, samples) if delay is None else (delay, samples)
    if delay is None:
        at, used = lag(np.ones(3))

    solved = solve_gains(phi, used.tau, tau0, moving, prior, (1, 2) if gains else (), residuals_with)
    estimated = solved[-1]
    scores: tuple[float, float, int] | None = None
    if gains:            # correct only the gains the log shows to differ from 1 (module doc, stage 3)
        values, sigma = estimated
        shown = tuple(j for j in (1, 2) if abs(values[j] - 1) > max(GAIN_NOTED, GAIN_EVIDENCE * sigma[j]))
        kept = at, used, solved
        if delay is None and shown:          # the delay again with the gains corrected: a joint's scale moves it
            scale = np.ones(3)
            scale[list(shown)] = values[list(shown)]
            at, used = lag(scale)
            solved = solve_gains(phi, used.tau, tau0, moving, prior, (1, 2), residuals_with)
            estimated = solved[-1]
        if shown:            # and only where the held-out prediction gets better (selection.py)
            scores = validate_gains(phi, used.tau, tau0, moving, prior, shown)
            if scores[2] < FOLDS:
                shown = ()
                at, used, solved = kept
                estimated = solved[-1]
        if shown != (1, 2):
            solved = solve_gains(phi, used.tau, tau0, moving, prior, shown, residuals_with)
    beta, covariance, information, log_beta, log_rms, (gain, _) = solved
    given = 0.0 if delay is None else delay      # both timings at zero delay when it is estimated
    residuals = {name: weighted(samples.at(HOLD[name] / samples.rate - given, gain).tau - tau0)
                 for name in TIMINGS}     # in joint 1's scale, the gains applied
    return _Timed(used, at, beta, covariance, information, log_beta, log_rms, gain, estimated, residuals,
                  _gain_scores(scores))


def _gain_scores(scores: tuple[float, float, int] | None) -> dict[str, float]:
    """The held-out check of the corrected gains (validate_gains) as the fit records it: {} where
    none was run."""
    return {} if scores is None else {"kept at 1": scores[0], "corrected": scores[1],
                                      "quarters better": float(scores[2])}


def _projection(ready: _Regression, beta: np.ndarray, covariance: np.ndarray,
                prior_weight: float) -> tuple[np.ndarray, np.ndarray]:
    """Stage 5: the structure's physical parameters nearest to ``beta`` in the metric of
    ``covariance`` (physical.nearest), and beta's standard deviations; LogError where the log
    alone (no prior) leaves a direction unconstrained."""
    structure = ready.structure
    sigma = np.sqrt(np.diag(covariance))
    if not np.isfinite(sigma).all():
        loose = ", ".join(structure.base_names[k].split(" = ")[0][:40] for k in np.flatnonzero(~np.isfinite(sigma))[:3])
        raise LogError(f"not exciting enough for the log alone: it leaves {loose} unconstrained; identify with "
                       "the prior (a finite prior_spread)", argument="prior_spread")
    return structure.nearest(beta, metric_root(covariance), prior_weight), sigma



def _comparison(structure: Structure, phantom: Phantom, samples: Samples) -> tuple[str, np.ndarray] | None:
    """The other structure's least-squares residual RMS per joint (N m), if it applies."""
    other = "report" if structure.name == "general" else "general"
    if other == "report" and phantom.config.report is None:
        return None
    phi, tau0 = STRUCTURES[other](phantom).regressor_of(samples.theta, samples.dtheta, samples.ddtheta,
                                                        samples.friction)
    return other, rms(least_squares(phi, samples.tau - tau0, samples.moving)[2], samples.moving)
