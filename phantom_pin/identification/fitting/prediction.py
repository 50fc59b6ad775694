"""The identified model judged by the torques it predicts, not by the regressor's condition.

The estimate's covariance C (estimation: the Gauss-Markov estimate with the prior, prior.py)
carried to the torques: at a state s, the joint torques tau = Phi_s beta have standard
deviation sqrt(diag(Phi_s C Phi_s^T)) (N m). Its RMS over a set of states, as a share of the
torque RMS there, per joint, is the model's predicted torque uncertainty: over the log's own
states, and over STATES seeded states inside the stops (config.sampling.random_states: rates 2
rad/s, accelerations 20 rad/s^2 standard deviation), the motion a user's controller asks of it.

The log leaves poorly excited the directions of the base parameters its information
Phi_w^T Phi_w / s^2 hardly sees: in the base parameters scaled by their typical size
(prior.typical), the eigenvectors of the information with the smallest eigenvalues lambda,
each uncertain by 1 / sqrt(lambda) of that size from the log alone. They are named by the base
parameters they combine; where that exceeds the prior's spread, the prior holds them.

What the covariance leaves out: it is the log's noise alone, and a model's error on unseen
motion is mostly the bias that the log's errors leave in it (the filtered rates' and
accelerations', the friction law's, the loop's), the same in every part of the log, which the
log cannot show: over the figures table's written models (benchmarks/identification_figures.py)
the held-out error on an unseen trajectory was a median 2.7 times that sigma on the worst joint.
So the expected error on unseen motion, ``Prediction.expected``, is that sigma times CALIBRATION,
a split-conformal factor: the 90 % quantile of the worst joint's held-out error over sigma on a
calibration set (the table's 96 written models at --seed 1: 9.51, the ceil(0.9 (n + 1))-th of
96), halved so that 2 sigma covers it and rounded up to a half. On the table itself (seed 0,
other trajectories, noise and held-out motion) 2 x expected covers the held-out error on every
joint in 92 of 96 written models (96 %); it says nothing of a device unlike the simulated ones
(module doc of the script). Set again whenever the estimate changes: it was 5.5 (10.98) before
the delay's quiet cutoff and the thresholds up to 0.5 rad/s.

When to refuse: with the prior as the estimate's mean, the prior's expected squared error at any
state is the fit's plus the squared change the log made, so on unseen states the written model
is never expected worse than the prior. What can be measured is the log itself: a written model
whose residual on the log exceeds the prior's on some joint (by WORSE) predicts worse than the
prior did, and is refused. Between, a joint whose predicted uncertainty over the states inside
the stops exceeds WARN_SHARE, or a direction the log leaves more than POORLY uncertain, is
warned about.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

import numpy as np

from phantom_pin.config.sampling import random_states
from phantom_pin.config.types import Limits
from phantom_pin.identification.fitting.least_squares import rms

#: The seeded states inside the stops the prediction is judged over (number, seed).
STATES, SEED = 200, 0
#: A joint predicted less well than this share of its torque RMS (1 sigma) is warned about.
WARN_SHARE = 0.01
#: A direction of the base parameters the log alone leaves more uncertain than this share of its
#: typical size is named as poorly excited.
POORLY = 0.1
#: The written model's residual on the log, against the prior's: refused above this ratio (markedly worse).
WORSE = 1.1
#: Most directions named.
NAMED = 3
#: The expected error on unseen motion over the log's noise alone (module doc: split-conformal,
#: benchmarks/identification_figures.py --seed 1, 96 written models: 9.51 / 2, rounded up).
CALIBRATION = 5.0


@dataclasses.dataclass(frozen=True)
class Prediction:
    """Predicted torque uncertainty (module doc), each a share of the torque RMS per joint (3,):
    ``log`` over the log's states and ``states`` over the states inside the stops; the written
    model's residual on the log, ``fit_log``, and the prior's, ``prior_log`` (measured);
    ``prior_states``: the RMS of the prior's torques less the written model's over the states
    (the prior's error if the fit is right); ``directions``: (words, relative standard deviation
    from the log alone) of the poorly excited directions, most uncertain first; ``spread``: the
    prior's relative standard deviation (inf: none)."""

    log: np.ndarray
    states: np.ndarray
    fit_log: np.ndarray
    prior_log: np.ndarray
    prior_states: np.ndarray
    directions: tuple[tuple[str, float], ...]
    spread: float

    @property
    def expected(self) -> np.ndarray:
        """The expected error on unseen motion inside the stops (1 sigma, share of the torque RMS
        per joint): ``states`` times CALIBRATION (module doc)."""
        return CALIBRATION * self.states

    def worse(self) -> str | None:
        """One line if the written model predicts the log's torques worse than the prior, else None."""
        joints = np.flatnonzero(self.fit_log > WORSE * self.prior_log)
        if not joints.size:
            return None
        return ("the identified model predicts the log's torques worse than the prior (residual "
                + ", ".join(f"joint {j + 1}: {100 * self.fit_log[j]:.3g} % of the torque RMS against the prior's "
                            f"{100 * self.prior_log[j]:.3g} %" for j in joints)
                + "): keep the configuration you passed, or check the log's units, signs and timing")

    def warnings(self) -> list[str]:
        """The lines that warn (module doc): joints predicted worse than WARN_SHARE, and the poorly
        excited directions."""
        lines = []
        uncertain = np.flatnonzero(self.states > WARN_SHARE)
        if uncertain.size:
            lines.append("predicted torque uncertainty over states inside the stops above "
                         f"{100 * WARN_SHARE:g} % on " + ", ".join(
                             f"joint {j + 1} ({100 * self.states[j]:.2g} %)" for j in uncertain)
                         + ": log a longer or wider motion (phantom-pin excite)")
        if self.directions:
            held = "" if not np.isfinite(self.spread) else \
                f"; where above {100 * self.spread:.0f} %, the prior holds them"
            lines.append("the log leaves poorly excited: " + "; ".join(
                f"{words}: {_percent(share)} uncertain" for words, share in self.directions)
                + f" (from the log alone, of their typical size{held})")
        return lines

    def lines(self) -> list[str]:
        """The prediction as printed and written in the overlay's header."""
        return ["predicted torque uncertainty (1 sigma, share of the torque RMS per joint): "
                + _joints(self.log) + " over the log's states, " + _joints(self.states)
                + f" over {STATES} states inside the stops (the log's noise alone)",
                "expected error on unseen motion (1 sigma, the model's errors included: the above times "
                f"{CALIBRATION:g}, calibrated on simulated devices): " + _joints(self.expected)
                + " over the states inside the stops",
                "residual on the log: " + _joints(self.fit_log) + "; the prior's: " + _joints(self.prior_log)
                + "; the prior's torques differ from the model's by " + _joints(self.prior_states)
                + " over the states inside the stops"]


def _joints(shares: np.ndarray) -> str:
    return ", ".join(f"{100 * s:.2g} %" for s in shares)


def _percent(share: float) -> str:
    return "more than 1000 %" if share > 10 else f"{100 * share:.2g} %" if share < 0.995 else f"{100 * share:.0f} %"


def torque_sigma(phi: np.ndarray, covariance: np.ndarray) -> np.ndarray:
    """The torques' standard deviations (N, 3) (N m) of phi (N, 3, P) beta with beta's covariance
    (P, P): sqrt(diag(Phi C Phi^T)) per state and joint."""
    return np.sqrt(np.maximum(np.einsum("njp,pq,njq->nj", phi, covariance, phi), 0.0))


def poorly_excited(information: np.ndarray, typical: np.ndarray, names: tuple[str, ...],
                   threshold: float = POORLY, count: int = NAMED) -> tuple[tuple[str, float], ...]:
    """The directions of the base parameters that ``information`` (P, P: the log's, in the inverse
    units squared of the base parameters) leaves more uncertain than ``threshold`` of their
    ``typical`` size, at most ``count``, most uncertain first: (words from ``names``, relative
    standard deviation)."""
    scaled = information * np.outer(typical, typical)
    values, vectors = np.linalg.eigh(0.5 * (scaled + scaled.T))
    out: list[tuple[str, float]] = []
    for value, vector in zip(values, vectors.T):
        share = 1 / np.sqrt(value) if value > 0 else np.inf
        if share <= threshold or len(out) == count:
            break
        out.append((_words(vector, names), float(share)))
    return tuple(out)


def _words(vector: np.ndarray, names: tuple[str, ...]) -> str:
    """A direction in words: its components of more than 0.2 of its square, largest first (at
    most three; the three largest when it spreads over many, none that large)."""
    ranked = [int(k) for k in np.argsort(-np.abs(vector), kind="stable")]
    order = [k for k in ranked if vector[k] ** 2 > 0.2][:3] or ranked[:3]
    if len(order) == 1:
        return _short(names[order[0]])
    sign = np.sign(vector[order[0]])
    return " ".join(f"{'+' if sign * vector[k] > 0 else '-'} {abs(vector[k]):.2f} ({_short(names[k])})"
                    for k in order).lstrip("+ ")


def _short(name: str) -> str:
    """A base parameter's name: its symbol (before " = "), or its first terms within 40 characters."""
    name = name.split(" = ")[0]
    return name if len(name) <= 40 else name[:40].rsplit(" ", 1)[0] + " ..."


def judge(regressor_of: Callable[..., tuple[np.ndarray, np.ndarray]], limits: Limits, phi: np.ndarray,
          y: np.ndarray, moving: np.ndarray,
          written: np.ndarray, covariance: np.ndarray, beta0: np.ndarray, information: np.ndarray,
          typical: np.ndarray, names: tuple[str, ...], spread: float) -> Prediction:
    """The Prediction of the base parameters ``written`` with ``covariance`` (module doc):
    ``regressor_of(theta, dtheta, ddtheta)`` -> (Phi, tau_0) of the structure; ``phi`` (N, 3, P),
    ``y`` (N, 3) (N m, less tau_0) and ``moving`` (N, 3) the log's fitted equations; ``beta0`` the
    prior's base parameters; ``information`` the log's (poorly_excited); ``typical`` the base
    parameters' typical sizes; ``names`` theirs; ``spread`` the prior's."""
    theta, dtheta, ddtheta = random_states(limits, STATES, SEED)
    phi_s, tau0_s = regressor_of(theta, dtheta, ddtheta)
    tau_s = rms(phi_s @ written + tau0_s)
    torque = rms(y, moving)
    return Prediction(log=rms(torque_sigma(phi, covariance), moving) / torque,
                      states=rms(torque_sigma(phi_s, covariance)) / tau_s,
                      fit_log=rms(y - phi @ written, moving) / torque,
                      prior_log=rms(y - phi @ beta0, moving) / torque,
                      prior_states=rms(phi_s @ (beta0 - written)) / tau_s,
                      directions=poorly_excited(information, typical, names), spread=spread)
