"""What identify chooses from the log itself, each on FOLDS held-out parts of it: the friction
speed threshold (choose_min_speed), the torque timing (choose_timing), and whether a torque gain
the evidence rule found is corrected (validate_gains). The threshold:

Near rest a joint sticks and its torque is whatever holds it, not the sliding friction law the
regressor describes (filtering.MIN_SPEED). How far from rest that reaches depends on the device:
on a Touch with Coulomb friction near joint 3's torque RMS, the default 0.01 rad/s kept the
sticking samples, and the fit answered with viscous friction 7-10 % off, a torque gain corrected
by 1 % and a delay of -0.72 ms, all at 10 standard deviations; from 0.02 rad/s up, every number
came back exact. Its effect reaches well beyond the rates at which a joint sticks: on a lab's 60 s sum of sines
(benchmarks/identification_figures.py) the largest threshold tried used to be 0.1 rad/s, and the
Touch with a Stribeck peak came back 0.67 / 0.87 % off (held-out trajectory / states), its clean
log 0.23 / 0.29 %; with 0.2, 0.3 and 0.5 tried, the choice is 0.5 rad/s and 0.065 / 0.084 %, clean
0.017 / 0.020 %. Tried up to 1 rad/s the choice stayed at or below 0.5 on those logs. So each
threshold of MIN_SPEEDS is tried on FOLDS contiguous parts of the log:
fitted (least squares with the prior, at the delay given or zero, gains at 1) on the others and
judged on the held-out part's samples where every threshold fits (the largest's equations; a
threshold that leaves a joint fewer than checks.MIN_SAMPLES / FOLDS equations in some part is not
tried), by the sum over the joints of the residual's mean square over the torque's. The smallest threshold
within SPEED_TIE of the best is chosen (it keeps the most samples).
"""

from __future__ import annotations

import numpy as np

from phantom_pin.dynamics.phantom import Phantom
from phantom_pin.exceptions import LogError
from phantom_pin.identification.data.io import Log
from phantom_pin.identification.data.timing import HOLD, TIMINGS
from phantom_pin.identification.fitting import checks
from phantom_pin.identification.fitting.filtering import Samples, filtered
from phantom_pin.identification.fitting.least_squares import fit as least_squares
from phantom_pin.identification.fitting.least_squares import solve_gains
from phantom_pin.identification.structure.structures import Structure

__all__ = ["choose_min_speed", "choose_timing", "validate_gains"]

#: The thresholds tried (rad/s), and the parts of the log each is judged on.
MIN_SPEEDS, FOLDS = (0.01, 0.02, 0.05, 0.1, 0.2, 0.3, 0.5), 4
#: A timing whose held-out residual is within TIE of the other's counts as as good, and so does a
#: threshold within SPEED_TIE of the best's. The thresholds are judged on the fastest equations
#: only, where sticking shows least: on the tests' 30 s sum of sines with a Stribeck peak
#: (tests/identification/data/test_timing.py) the scores from 0.02 to 0.5 rad/s lay within 2 %, and a
#: 2 % tie chose 0.02 rad/s, whose fit was 0.82 % off on 500 states (viscous friction 10 % low);
#: within 1 %, 0.05 rad/s and 0.41 % (2 %).
TIE, SPEED_TIE = 0.02, 0.01
#: Held-out residuals within this share of each other are equal: a corrected gain counts as
#: better on a part only below (1 - ROUNDING) times the uncorrected fit's residual. The BLAS
#: kernels' rounding moves these figures by up to 4e-6 (relative, Sandybridge against Haswell;
#: DEVELOPERS.md), a real gain error's improvement is 0.3-1 % a part: a fixed rule decides
#: where the kernel would otherwise.
ROUNDING = 1e-4


def choose_min_speed(log: Log, phantom: Phantom, structure: Structure, cutoff: float, timing: str, delay: float,
                     prior: tuple[np.ndarray, np.ndarray] | None) -> tuple[float, dict[float, float], Samples]:
    """(the threshold chosen, rad/s; each threshold's held-out weighted residual: the module doc;
    the log filtered for the chosen one) of ``log`` on ``structure`` (a Structure of ``phantom``)
    filtered at ``cutoff`` Hz with the torques at ``timing`` and ``delay`` s; ``prior``:
    (beta_0, P) or None. LogError (the smallest threshold's) where none leaves enough motion."""
    law = phantom.config.actuation.friction
    candidates: dict[float, Samples] = {}
    refused: LogError | None = None
    for speed in MIN_SPEEDS:
        candidate = filtered(log, cutoff, law, timing, delay, speed)
        try:
            checks.refuse_motion(candidate.moving, cutoff, speed)
        except LogError as error:
            refused = refused or error
            continue
        candidates[speed] = candidate
    if not candidates:
        assert refused is not None
        raise refused
    samples = next(iter(candidates.values()))         # all alike but for moving
    part = parts(len(samples.theta))
    # judged on the largest threshold's equations: each joint needs some in every part
    counts = {speed: min(int((c.moving & (part == k)[:, None]).sum(axis=0).min()) for k in range(FOLDS))
              for speed, c in candidates.items()}
    moving = {speed: c.moving for speed, c in candidates.items() if counts[speed] >= checks.MIN_SAMPLES / FOLDS
              or speed == min(candidates)}
    phi, tau0 = structure.regressor_of(samples.theta, samples.dtheta, samples.ddtheta, samples.friction)
    y = samples.tau - tau0
    judged = moving[max(moving)]                                           # where every threshold fits
    scores = {speed: _held_out(phi, y, mask, judged, part, prior) for speed, mask in moving.items()}
    best = min(scores.values())
    chosen = min(speed for speed, score in scores.items() if score <= (1 + SPEED_TIE) * best)
    return chosen, scores, candidates[chosen]


def _held_out(phi: np.ndarray, y: np.ndarray, mask: np.ndarray, judged: np.ndarray, part: np.ndarray,
              prior: tuple[np.ndarray, np.ndarray] | None) -> float:
    """The weighted residual (sum over the joints of the residual's mean square over the
    torque's) on each part's ``judged`` equations of the fit on the other parts' ``mask`` ones."""
    residual, torque = np.zeros(3), np.zeros(3)
    for k in range(part.max() + 1):
        train, test = mask & (part != k)[:, None], judged & (part == k)[:, None]
        beta = least_squares(phi, y, train, prior)[0]
        residual += (((y - phi @ beta) * test) ** 2).sum(axis=0)
        torque += ((y * test) ** 2).sum(axis=0)
    return float((residual / np.maximum(torque, 1e-300)).sum())


def parts(n: int) -> np.ndarray:
    """Each of ``n`` samples' part of the log (0..FOLDS-1): FOLDS contiguous parts, in time order."""
    return np.minimum((np.arange(n) * FOLDS) // n, FOLDS - 1)


def validate_gains(phi: np.ndarray, tau: np.ndarray, tau0: np.ndarray, moving: np.ndarray,
                   prior: tuple[np.ndarray, np.ndarray] | None, free: tuple[int, ...]) -> tuple[float, float, int]:
    """(the held-out weighted residual of the fit with every torque gain at 1; of the fit that
    estimates the gains of the joints ``free`` (least_squares.solve_gains) on the other parts and
    corrects the held-out part's torques by them; the number of parts on which the second is
    below the first by more than ROUNDING). The weighted residual is the module doc's (the sum over the joints of the
    residual's mean square over the torque's), each part judged by the fit on the others.
    ``phi`` (N, 3, P) zeroed outside ``moving`` (N, 3), ``tau`` and ``tau0`` (N, 3; N m) the
    logged and the known torques, ``prior`` (beta_0, P) or None."""
    part = parts(len(tau))
    residual, torque = np.zeros((2, FOLDS, 3)), np.zeros((2, FOLDS, 3))
    for k in range(FOLDS):
        train, test = moving & (part != k)[:, None], moving & (part == k)[:, None]
        for corrected in (0, 1):
            if corrected:
                solved = solve_gains(phi, tau, tau0, train, prior, free)
                beta, gain = solved[0], solved[-1][0]
            else:
                beta, gain = least_squares(phi, tau - tau0, train, prior)[0], np.ones(3)
            y = gain * tau - tau0                 # in joint 1's torque scale
            residual[corrected, k] = (((y - phi @ beta) * test) ** 2).sum(axis=0)
            torque[corrected, k] = ((y * test) ** 2).sum(axis=0)
    each = (residual / np.maximum(torque, 1e-300)).sum(axis=-1)                  # (2, FOLDS)
    total = (residual.sum(axis=1) / np.maximum(torque.sum(axis=1), 1e-300)).sum(axis=-1)
    return float(total[0]), float(total[1]), int((each[1] < (1 - ROUNDING) * each[0]).sum())


def choose_timing(samples: Samples, phi: np.ndarray, tau0: np.ndarray, delay: float,
                  prior: tuple[np.ndarray, np.ndarray] | None) -> tuple[str, dict[str, float]]:
    """(the torque timing chosen, each timing's held-out weighted residual: the module doc's) of
    ``samples`` with the torques read at each timing's lag (timing.HOLD) and ``delay`` (s), on
    ``phi`` (N, 3, P) zeroed outside ``samples.moving`` less ``tau0`` (N, 3; N m); ``prior``:
    (beta_0, P) or None. "held" (a servo loop's commands) unless "sampled" leaves less than
    (1 - TIE) times its residual."""
    part, moving = parts(len(tau0)), samples.moving
    scores = {name: _held_out(phi, samples.at(HOLD[name] / samples.rate - delay).tau - tau0, moving, moving, part,
                              prior) for name in TIMINGS}
    return ("sampled" if scores["sampled"] < (1 - TIE) * scores["held"] else "held"), scores
