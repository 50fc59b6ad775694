"""The result of estimation.estimate: the base parameters with their uncertainty, the physical
parameters written, and what the log showed (timing, gains, residuals, problems)."""

from __future__ import annotations

import dataclasses

import numpy as np

from phantom_pin.identification.fitting.prediction import Prediction


@dataclasses.dataclass(frozen=True)
class Curves:
    """The fitted samples as identify --report draws them: ``t`` (N,) s, the log's times of the
    kept samples; ``dtheta`` (N, 3) rad/s, filtered; ``measured`` (N, 3) N m, the filtered torques
    at the fitted timing and delay, in joint 1's torque scale (the gains applied); ``predicted``
    (N, 3) N m, the written model's (its base regressor times the written base parameters, the
    known parts added); ``friction`` (N, 3) N m, the written friction's share of ``predicted``;
    ``moving`` (N, 3) bool, the equations fitted."""

    t: np.ndarray
    dtheta: np.ndarray
    measured: np.ndarray
    predicted: np.ndarray
    friction: np.ndarray
    moving: np.ndarray


@dataclasses.dataclass(frozen=True, kw_only=True)
class Fit:
    """Result of ``estimate``.

    ``structure`` ("general" or "report"); ``names``, ``units``: the base parameters, each a
    sum of physical parameters; ``beta``, ``sigma``: their estimates and standard deviations
    (with the prior: the stages in the module doc); ``rms``: the residual RMS per joint (N m) of
    beta, ``written_rms`` of the written parameters, ``torque_rms`` the torque's RMS (N m);
    ``condition`` of the base regressor (columns scaled to unit norm: a diagnostic only);
    ``samples`` used; ``x``: the physical parameters (Structure.names: the structure's, then
    viscous1..3 N m s/rad, coulomb1..3 N m), ``written`` = their beta, ``overrides`` their
    --params keys (without friction: overlays.overlay); ``comparison``: (name, residual RMS per
    joint, N m) of the other structure, or None; ``gains`` (3,): each joint's torque gain
    relative to joint 1 as corrected (the log's tau_j times gains_j is the torque the model
    predicts; joint 1's is 1; 1 where not corrected), ``gains_estimated``: (estimates (3,),
    standard deviations (3,)), all 1 and 0 when not estimated, ``ratios`` the model's
    transmission ratios (None: not public); ``problems``: why the result should not be written
    (one line each; empty for a usable log). ``prior_beta`` the prior's base parameters,
    ``log_beta`` and ``log_sigma`` the log's alone (inf where it leaves a direction
    unconstrained), ``log_rms`` its residual RMS per joint (N m: whether the torques follow the
    motion at all); ``prediction``: the predicted torque uncertainty of the written parameters
    (prediction.Prediction). ``delay`` (s): how long after their positions the torques were
    logged, corrected for in the fit; ``delay_estimated``: whether it came from the log;
    ``delay_cutoff``: (the cutoff it was estimated at, Hz; each
    cutoff tried and the share of the angles' noise in its filtered acceleration, worst joint:
    filtering.quiet_cutoff; empty where not estimated or where instrumented);
    ``timing`` the torque timing fitted (timing.TIMINGS); ``timing_residual``: each timing's
    weighted residual (the sum over the joints of the residual's mean square over the
    torque's, at zero delay when it is estimated, else at the given one), the smaller fitting
    the log better. ``curves``: the samples fitted, measured and predicted (Curves).
    ``min_speed`` (rad/s): the friction speed threshold fitted with; ``min_speed_scores``: each
    threshold's held-out weighted residual where it was chosen from the log (selection.py), else
    empty. ``gain_scores``: where a torque gain passed the evidence rule (estimation.GAIN_NOTED,
    GAIN_EVIDENCE), the held-out weighted residual of the fit with the gains "kept at 1" and
    "corrected" (selection.validate_gains; corrected only where better by estimation.GAIN_TIE),
    else empty. ``closed_loop``: where the log was identified as a closed loop on a reference given,
    the line that says so (instrumental variables, instruments.py), else empty."""

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
    problems: tuple[str, ...] = ()
    prior_beta: np.ndarray
    log_beta: np.ndarray
    log_sigma: np.ndarray
    log_rms: np.ndarray
    prediction: Prediction
    delay: float = 0.0
    delay_estimated: bool = False
    delay_cutoff: tuple[float, dict[float, float]] = dataclasses.field(default_factory=lambda: (20.0, {}))
    timing: str = "held"
    timing_residual: dict[str, float] = dataclasses.field(default_factory=dict)
    ratios: tuple[float, float, float] | None = None
    curves: Curves | None = None
    min_speed: float = 0.01          # filtering.MIN_SPEED (not imported: fit.py stays below filtering)
    min_speed_scores: dict[float, float] = dataclasses.field(default_factory=dict)
    closed_loop: str = ""
    gain_scores: dict[str, float] = dataclasses.field(default_factory=dict)
    timing_scores: dict[str, float] = dataclasses.field(default_factory=dict)

    @property
    def friction(self) -> tuple[np.ndarray, np.ndarray]:
        """(estimates, standard deviations) of viscous1..3 (N m s/rad) and coulomb1..3 (N m)."""
        return self.beta[-6:], self.sigma[-6:]
