"""Identification as a user runs it: ``identify(log, phantom)`` estimates (estimation.py), refuses
a log with problems unless accepted, and returns an ``Identification`` that reports in words
(``report``, ``warnings``) and writes itself as a --params overlay (``write``); the sentences a
user reads about a Fit live here, in the module that prints them.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from pathlib import Path

import numpy as np

from phantom_pin.dynamics.phantom import Phantom
from phantom_pin.identification.data.io import Log
from phantom_pin.identification.data.timing import LEAD, TIMING_MARGIN
from phantom_pin.identification.fitting.checks import GAIN_BOUNDS, RefusedError, refusal
from phantom_pin.identification.fitting.estimation import GAIN_EVIDENCE, GAIN_NOTED, NEEDS_GENERAL, Fit, estimate
from phantom_pin.identification.fitting.filtering import CUTOFF, NOISE_SHARE
from phantom_pin.identification.fitting.selection import FOLDS, TIE
from phantom_pin.identification.structure import prior as priors
from phantom_pin.identification.verdict.overlays import overlay, write_yaml, yaml_text

__all__ = ["Identification", "RefusedError", "identify", "refusal"]


@dataclasses.dataclass(frozen=True)
class Identification:
    """The result of ``identify``: the ``fit`` (estimation.Fit), the overlay's ``keys`` and
    ``notes`` (overlays.overlay: checked to give a physical model), the ``source`` the log came
    from (its file name), its ``rate`` (Hz) and ``rows``, and the ``cutoff`` (Hz) it was filtered at."""

    fit: Fit
    keys: dict[str, object]
    notes: list[str]
    source: str
    rate: float
    rows: int
    cutoff: float

    def report(self) -> list[str]:
        """What identify prints: the log used, the timing and gains, the predicted uncertainty,
        the residual, the structures compared, each base parameter (one line each)."""
        fit = self.fit
        lines = [f"{self.rows} samples at {self.rate:.6g} Hz, {fit.samples} used (filtered at {self.cutoff:g} Hz); "
                 f"{fit.structure} structure, {len(fit.beta)} base parameters; condition number {fit.condition:.3g} "
                 "(a diagnostic: the fit is judged by its predicted torques)"]
        lines += [fit.closed_loop] if fit.closed_loop else []
        lines += timing_lines(fit) + [speed_line(fit)] + gain_lines(fit) + fit.prediction.lines()
        lines.append("residual RMS per joint [N m]: " + ", ".join(
            f"{r:.3g} ({100 * r / s:.2f} % of {s:.3g})" for r, s in zip(fit.rms, fit.torque_rms))
            + "; of the written parameters: " + ", ".join(f"{r:.3g}" for r in fit.written_rms))
        if fit.comparison is not None:
            name, values = fit.comparison
            lines.append(f"the {name} structure leaves " + ", ".join(f"{r:.3g}" for r in values) + " N m RMS ("
                         + ", ".join(f"{100 * r / s:.2f} %" for r, s in zip(values, fit.torque_rms)) + ")")
        advice = recommendation(fit)
        if advice:
            lines.append(f"recommendation: {advice}")
        elif fit.comparison is not None:
            lines.append(f"the report's structure suffices for this log (within {NEEDS_GENERAL} times the general "
                         "model's residual on every joint)")
        lines.append(f"{'':6} {'estimate':>12} {'std dev':>10} {'written':>12} {'log alone':>12} {'prior':>12}  "
                     f"{'unit':9} base parameter")
        lines += [f"beta{k + 1:<2} {fit.beta[k]:12.5g} {fit.sigma[k]:10.2g} {fit.written[k]:12.5g} "
                  f"{fit.log_beta[k]:12.5g} {fit.prior_beta[k]:12.5g}  {unit:9} {name}"
                  for k, (name, unit) in enumerate(zip(fit.names, fit.units))]
        return lines + self.notes

    def warnings(self) -> list[str]:
        """The warnings (one line each): the prediction's, the timing's and the gains', then the
        problems of a fit accepted despite them."""
        fit = self.fit
        return (fit.prediction.warnings() + fit_warnings(fit)
                + [f"(written with --accept) {problem}" for problem in fit.problems])

    def write(self, path: Path | str, force: bool = False) -> None:
        """Write the overlay (text()) to ``path`` (YAML); an existing file only with ``force``
        (InvalidInputError naming ``path`` otherwise)."""
        write_yaml(path, self.text(), force=force)

    def text(self) -> str:
        """The overlay: dotted --params keys (SI units) with the fit in comments (yaml_text), as YAML text."""
        fit = self.fit
        lines = [f"Identified by phantom-pin identify from {self.source} ({fit.structure} structure): a --params",
                 "overlay for phantom-pin urdf/srdf/mjcf/simulate/... and describe(overrides=read_overrides(...))",
                 "(docs/identification.md). SI units.",
                 f"{fit.samples} samples, base regressor condition number {fit.condition:.3g} (a diagnostic); "
                 "residual RMS per joint [N m]: " + " ".join(f"{v:.3g}" for v in fit.rms)]
        lines += timing_lines(fit) + [speed_line(fit)] + gain_lines(fit)
        lines += [f"warning: {w}" for w in fit_warnings(fit)]
        lines += fit.prediction.lines()
        lines += [f"warning: {line}" for line in fit.prediction.warnings()]
        lines += ["base parameters (estimate with the prior +- standard deviation; of the written parameters; "
                  "of the log alone; the prior's):"]
        lines += [f"  beta{k + 1} = {fit.beta[k]:.6g} +- {fit.sigma[k]:.2g} {unit}; written {fit.written[k]:.6g}; "
                  f"log alone {fit.log_beta[k]:.6g}; prior {fit.prior_beta[k]:.6g}: {name}"
                  for k, (name, unit) in enumerate(zip(fit.names, fit.units))]
        lines += list(self.notes)
        lines += [f"problem, written with --accept: {problem}" for problem in fit.problems]
        lines += ["What the log does not excite comes from the model's values (the prior, within its stated "
                  f"{100 * fit.prediction.spread:.0f} % spread)." if np.isfinite(fit.prediction.spread) else
                  "Directions the torques do not determine are kept near the model's values (the prior)."]
        return yaml_text(lines, self.keys)


def identify(log: Log, phantom: Phantom, *, cutoff: float = CUTOFF, structure: str = "general",
             timing: str | None = None, prior_spread: float = priors.SPREAD, delay: float | None = None,
             gains: bool = True, min_speed: float | None = None, accept: bool = False,
             given: dict[str, object] | None = None, source: str = "a log",
             progress: Callable[[float], None] | None = None,
             reference: tuple[np.ndarray, np.ndarray] | None = None) -> Identification:
    """Identify the device of ``log`` (read_log: theta rad, tau N m in the report's convention)
    on ``phantom`` (its parameters the prior): estimation.estimate with these arguments (its
    docstring has their units), then the overlay's keys (overlays.overlay, with the overrides
    ``given`` the model was made with). Without ``accept``, a log with problems raises
    RefusedError: those found before any fit (the torques' unit, a joint's sign) before any
    costly stage, the others after the fit. ``source``: the log's name in the overlay.
    ``reference``: (t s, theta rad) the motion a closed loop tracked (estimate's: instrumental variables)."""
    fit = estimate(log, phantom, cutoff, structure, progress=progress, timing=timing, prior_spread=prior_spread,
                   delay=delay, gains=gains, min_speed=min_speed, refuse=not accept, reference=reference)
    if fit.problems and not accept:
        raise RefusedError(fit.problems)
    keys, notes = overlay(fit, given, phantom.config)  # checked: a physical model, or nothing written
    return Identification(fit, keys, notes, source, log.rate, log.t.size, cutoff)


def speed_line(fit: Fit) -> str:
    """The friction speed threshold fitted with: given, or chosen on held-out parts of the log."""
    if not fit.min_speed_scores:
        return f"friction speed threshold: {fit.min_speed:g} rad/s (given; a joint's equation is fitted above it)"
    return (f"friction speed threshold: {fit.min_speed:g} rad/s, chosen on held-out quarters of the log (weighted "
            "residual: " + ", ".join(f"{speed:g} rad/s {100 * np.sqrt(score / 3):.3g} %" for speed, score in
                                     fit.min_speed_scores.items()) + " of the torque RMS)")


def timing_lines(fit: Fit) -> list[str]:
    """The delay (estimated or given, ms) and which timing fits the log better, one line each."""
    cutoff, shares = fit.delay_cutoff
    how = "estimated from the log" if fit.delay_estimated else "given"
    if shares and (len(shares) > 1 or shares[cutoff] > NOISE_SHARE):
        how += (f" filtered at {cutoff:g} Hz, where the angles' noise is " + ", ".join(
            f"{100 * share:.2g} % at {c:g} Hz" for c, share in shares.items()) + " of the filtered acceleration")
        if shares[cutoff] > NOISE_SHARE:
            why = "; the quieter cutoffs leave too little motion" if min(shares.values()) <= NOISE_SHARE else ""
            how += f" (above the {100 * NOISE_SHARE:g} % aimed at{why})"
    lines = [f"delay between positions and torques: {1e3 * fit.delay:.3f} ms ({how}; the torques are read "
             f"that long after their positions, then the {fit.timing} timing's lag)"]
    if fit.timing_scores:
        at = "no delay" if fit.delay_estimated else f"the given {1e3 * fit.delay:.3g} ms delay"
        lines.append(f"torque timing: {fit.timing}, chosen on held-out quarters of the log with {at} (weighted "
                     "residual: " + ", ".join(f"{name} {100 * np.sqrt(value / 3):.3g} %" for name, value in
                                              fit.timing_scores.items())
                     + f" of the torque RMS; held unless sampled is {100 * TIE:g} % better; --torque-timing "
                     "gives it)")
    elif len(fit.timing_residual) == 2:
        best = min(fit.timing_residual, key=lambda name: fit.timing_residual[name])
        at = "no delay" if fit.delay_estimated else f"the given {1e3 * fit.delay:.3g} ms delay"
        lines.append(f"torque timing: {best} fits the log better with {at} (weighted residual: "
                     + ", ".join(f"{name} {100 * np.sqrt(value / 3):.3g} %" for name, value in
                                 fit.timing_residual.items())
                     + f" of the torque RMS); identified as {fit.timing}"
                     + ("; the estimated delay absorbs the timings' half-sample difference" if
                        fit.delay_estimated else ""))
    return lines


def fit_warnings(fit: Fit) -> list[str]:
    """The timing's, the delay's and the gains' warnings (one line each; the prediction's are
    Prediction.warnings)."""
    return [w for w in (timing_warning(fit), lead_warning(fit), gain_warning(fit)) if w]


def lead_warning(fit: Fit) -> str | None:
    """One line when the delay estimated from the residual has the torques lead their positions
    by more than timing.LEAD: a servo loop's noise fed back into the motion, which biases the fit
    (instrumented, with --reference, the delay is estimated otherwise), else None."""
    if not fit.delay_estimated or fit.closed_loop or fit.delay >= -LEAD:
        return None
    return (f"the estimated delay, {1e3 * fit.delay:.3f} ms, has the torques logged before the positions they "
            f"belong to, by more than {1e3 * LEAD:g} ms: not a servo loop's logger, but how torque noise the loop "
            "feeds back into the motion (an amplifier's current noise) looks to the residual, and the friction, gains "
            "and rigid body are then biased; give the trajectory the loop tracked (--reference TRAJ.csv: "
            "instrumental variables), or --delay where you know the logger's")


def timing_warning(fit: Fit) -> str | None:
    """One line when the timing given fits the log worse than the other by more than
    TIMING_MARGIN of its weighted residual, else None."""
    if len(fit.timing_residual) != 2 or fit.timing_scores:      # chosen from the log: nothing to warn
        return None
    other = next(name for name in fit.timing_residual if name != fit.timing)
    chosen, alternative = fit.timing_residual[fit.timing], fit.timing_residual[other]
    if chosen <= (1 + TIMING_MARGIN) * alternative:
        return None
    return (f"--torque-timing {fit.timing} fits the log worse than {other} (weighted residual "
            f"{chosen / alternative:.3g} times, more than {1 + TIMING_MARGIN:g})"
            + (f" with no delay: the estimated delay, {1e3 * fit.delay:.3f} ms, takes up the half sample "
               f"between them; if the log has no delay, identify with --torque-timing {other}"
               if fit.delay_estimated else f"; identify with --torque-timing {other}"))


def gain_lines(fit: Fit) -> list[str]:
    """The joints' torque gains relative to joint 1, as estimated (the corrected ones as
    applied: estimated again with the others at 1) and what became of them, one line."""
    values, sigma = fit.gains_estimated
    if not sigma.any() and fit.closed_loop:
        return ["torque gains: not estimated (a closed loop given its reference: instrumented, unmodelled friction "
                "biases them): the log's torques taken as they are"]
    if not sigma.any():
        return ["torque gains: not estimated (--fixed-gains / gains=False): the log's torques taken as they are"]
    rejected = rejected_gains(fit)
    lines = ["torque gains relative to joint 1 (the log's torques times these are the model's): " + ", ".join(
        f"joint{j + 1} " + (f"{fit.gains[j]:.6g} +- {sigma[j]:.2g} (corrected in the written model)"
                            if fit.gains[j] != 1 else f"{values[j]:.6g} +- {sigma[j]:.2g} (kept at 1: correcting "
                            "it did not improve the held-out prediction)" if j in rejected else
                            f"{values[j]:.6g} +- {sigma[j]:.2g} (within {GAIN_EVIDENCE:g} standard deviations or "
                            f"{100 * GAIN_NOTED:g} % of 1: kept at 1)")
        for j in (1, 2))]
    if fit.gain_scores:
        kept, corrected = fit.gain_scores["kept at 1"], fit.gain_scores["corrected"]
        lines.append("torque gain correction checked on held-out quarters of the log (weighted residual: kept at 1 "
                     f"{100 * np.sqrt(kept / 3):.3g} %, corrected {100 * np.sqrt(corrected / 3):.3g} % of the "
                     f"torque RMS; corrected better on {fit.gain_scores['quarters better']:.0f} of {FOLDS} quarters): "
                     f"{'kept at 1' if rejected else 'corrected'} (corrected only where better on every quarter)")
    return lines


def rejected_gains(fit: Fit) -> list[int]:
    """The joints whose gain passed the evidence rule but was kept at 1: correcting them did not
    improve the held-out prediction (Fit.gain_scores)."""
    if not fit.gain_scores or (fit.gains != 1).any():
        return []
    values, sigma = fit.gains_estimated
    return [j for j in (1, 2) if abs(values[j] - 1) > max(GAIN_NOTED, GAIN_EVIDENCE * sigma[j])]


def gain_warning(fit: Fit) -> str | None:
    """One line naming the gains corrected (what to write into the driver) and those kept at 1
    that the estimate puts more than GAIN_NOTED from it (the log cannot tell), else None."""
    values, sigma = fit.gains_estimated
    off = [j for j in (1, 2) if fit.gains[j] != 1 and GAIN_BOUNDS[0] <= fit.gains[j] <= GAIN_BOUNDS[1]]
    rejected = rejected_gains(fit)
    unsure = [j for j in (1, 2) if fit.gains[j] == 1 and sigma[j] > 0 and abs(values[j] - 1) > GAIN_NOTED
              and j not in rejected]
    parts = []
    if off:
        parts.append(_corrected(fit, off))
    if unsure:
        parts.append(", ".join(f"joint {j + 1}'s torque gain ({values[j]:.4g} +- {sigma[j]:.2g})" for j in unsure)
                     + f": kept at 1, the log cannot show it differs (needs {GAIN_EVIDENCE:g} standard "
                     "deviations); a log that moves joint 1 more (phantom-pin excite) would tell")
    if rejected:
        parts.append(_rejected(fit, rejected))
    return "; ".join(parts) or None


def _corrected(fit: Fit, off: list[int]) -> str:
    """gain_warning's part on the gains corrected (joints ``off``): what to write into the driver."""
    hint = "" if fit.ratios is None else " (or were they converted with transmission ratio " + ", ".join(
        f"{fit.ratios[j] / fit.gains[j]:.4g} instead of the model's {fit.ratios[j]:.4g}" for j in off) + "?)"
    return (" and ".join(f"tau{j + 1} is {1 / fit.gains[j]:.4g} times" for j in off)
            + " joint 1's torque scale (gain " + ", ".join(f"{fit.gains[j]:.4g}" for j in off)
            + "): corrected in the written model; multiply " + " and ".join(
                f"joint {j + 1}'s torque constant in your driver by {fit.gains[j]:.4g}" for j in off)
            + f" so that its commands are the model's torques{hint}")


def _rejected(fit: Fit, rejected: list[int]) -> str:
    """gain_warning's part on the gains kept at 1 though the evidence rule passed (joints
    ``rejected``): the held-out prediction did not improve."""
    values, sigma = fit.gains_estimated
    kept, corrected = (100 * np.sqrt(fit.gain_scores[name] / 3) for name in ("kept at 1", "corrected"))
    return (", ".join(f"joint {j + 1}'s torque gain ({values[j]:.4g} +- {sigma[j]:.2g})" for j in rejected)
            + f": kept at 1 (the prior's), the log cannot tell: correcting it did not improve the held-out "
            f"prediction on every quarter of the log (better on {fit.gain_scores['quarters better']:.0f} of "
            f"{FOLDS}; {corrected:.3g} % of the torque RMS against {kept:.3g} % kept at 1); a log that "
            "moves joint 1 more (phantom-pin excite) would tell")


def recommendation(fit: Fit) -> str | None:
    """One line if the log shows the general model is needed (the report's structure leaves
    more than NEEDS_GENERAL times its residual on a joint), else None."""
    if fit.comparison is None:
        return None
    general, report = (fit.log_rms, fit.comparison[1]) if fit.structure == "general" else \
        (fit.comparison[1], fit.log_rms)          # both the log alone's fits
    ratio = float((report / general).max())
    if ratio <= NEEDS_GENERAL:
        return None
    return (f"the report's structure leaves up to {ratio:.2f} times the general model's residual (threshold "
            f"{NEEDS_GENERAL}): this device has products of inertia or off-axis centres of mass; "
            + ("keep the general structure's result" if fit.structure == "general"
               else "identify with --structure general"))
