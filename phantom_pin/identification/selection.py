"""The friction speed threshold chosen from the log itself, on held-out parts of it.

Near rest a joint sticks and its torque is whatever holds it, not the sliding friction law the
regressor describes (filtering.MIN_SPEED). How far from rest that reaches depends on the device:
on a Touch with Coulomb friction near joint 3's torque RMS, the default 0.01 rad/s kept the
sticking samples, and the fit answered with viscous friction 7-10 % off, a torque gain corrected
by 1 % and a delay of -0.72 ms, all at 10 standard deviations; from 0.02 rad/s up, every number
came back exact. So each threshold of MIN_SPEEDS is tried on FOLDS contiguous parts of the log:
fitted (least squares with the prior, at the delay given or zero, gains at 1) on the others and
judged on the held-out part's samples where every threshold fits (the largest's equations), by
the sum over the joints of the residual's mean square over the torque's. The smallest threshold
within TIE of the best is chosen (it keeps the most samples).
"""

from __future__ import annotations

import numpy as np

from phantom_pin.dynamics.model import Phantom
from phantom_pin.exceptions import LogError
from phantom_pin.identification import checks
from phantom_pin.identification.filtering import Samples, filtered
from phantom_pin.identification.io import Log
from phantom_pin.identification.least_squares import fit as least_squares
from phantom_pin.identification.structures import Structure

__all__ = ["choose_min_speed"]

#: The thresholds tried (rad/s), and the parts of the log each is judged on.
MIN_SPEEDS, FOLDS = (0.01, 0.02, 0.05, 0.1), 4
#: A threshold whose held-out residual is within this share of the best's counts as as good.
TIE = 0.02


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
    moving = {speed: candidate.moving for speed, candidate in candidates.items()}
    samples = next(iter(candidates.values()))         # all alike but for moving
    phi, tau0 = structure.regressor_of(samples.theta, samples.dtheta, samples.ddtheta, samples.friction)
    y = samples.tau - tau0
    judged = moving[max(moving)]                                           # where every threshold fits
    part = np.minimum((np.arange(len(y)) * FOLDS) // len(y), FOLDS - 1)
    scores = {speed: _held_out(phi, y, mask, judged, part, prior) for speed, mask in moving.items()}
    best = min(scores.values())
    chosen = min(speed for speed, score in scores.items() if score <= (1 + TIE) * best)
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
