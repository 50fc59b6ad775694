"""Gravity from rest: what a device's holding torques at still postures determine, for labs that
cannot run an exciting trajectory (docs/identification.md, "From rest postures").

At rest the joint torques are the gravity torques G(theta) = Phi_g(theta) beta (the regressor at
zero rates and accelerations; friction at rest is whatever holds the arm, within its Coulomb
bound, and is averaged out only when a posture is approached from both sides). Over the postures
inside the stops Phi_g spans a few directions of the base parameters, gamma = V^T beta
(``GRAVITY_POSTURES`` seeded postures: four for the PHANToM arms); the rest data determine those
they excite. Fit: the Gauss-Markov estimate of gamma with the prior (least_squares.fit; prior.py:
the configuration's own parameters), carried to every base parameter by the prior's correlation
(the conditional mean of beta given gamma), then the physical projection as for a trajectory.
Where the postures determine fewer than all of gamma, the one knob the data support is fitted: a
scale s on the model's gravity (every link's mass, first and second moments scaled alike), as
Force Dimension's SDK offers.

The result says how well gravity is now predicted at ``CHECK_POSTURES`` seeded postures inside
the stops (the fit's covariance carried to the torques, 1 sigma per joint as a share of the
gravity RMS there), which of the given postures are the fewest that determine it, and which
postures to add (greedily, those that most raise the smallest singular value of the scaled
gravity regressor).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from phantom_pin.config.sampling import sample_postures
from phantom_pin.dynamics.phantom import Phantom
from phantom_pin.exceptions import InvalidInputError, LogError
from phantom_pin.identification.data.io import Log
from phantom_pin.identification.fitting.least_squares import metric_root
from phantom_pin.identification.structure import prior as priors
from phantom_pin.identification.structure.structures import General, Structure

__all__ = ["Rest", "Gravity", "rest_of", "estimate_gravity"]

#: Seeded postures that give the gravity directions, and the check's (number, seed).
GRAVITY_POSTURES, CHECK_POSTURES, SEED = 2000, 500, 0
#: A singular value of the gravity regressor below this share of the largest is no direction.
RANK_TOLERANCE = 1e-9
#: Rest in a log: every joint slower than REST_SPEED (rad/s, over a 20 ms average) for at least
#: REST_HOLD (s); the first and last REST_TRIM (s) of each stretch are dropped (settling).
REST_SPEED, REST_HOLD, REST_TRIM = 0.01, 0.5, 0.1
#: Postures suggested at most.
SUGGESTED = 3
#: The holding torques' noise, as a share of their RMS per joint: estimated from the residual
#: where the equations exceed the gravity directions by MIN_DOF, else NOISE_ASSUMED (a current
#: loop's ripple and the breakaway friction a posture is held within: ESTIMATE), never below
#: NOISE_FLOOR (two postures fitting exactly are no proof of exact torques).
MIN_DOF, NOISE_ASSUMED, NOISE_FLOOR = 4, 0.02, 0.002


@dataclasses.dataclass(frozen=True)
class Rest:
    """Postures held still and their holding torques: ``theta`` (N, 3) rad, the report's, and
    ``tau`` (N, 3) N m, finite."""

    theta: np.ndarray
    tau: np.ndarray

    def __post_init__(self) -> None:
        theta, tau = (np.asarray(x, dtype=float) for x in (self.theta, self.tau))
        if theta.ndim != 2 or theta.shape[1:] != (3,) or tau.shape != theta.shape or not len(theta):
            raise LogError(f"expected theta and tau of shape (N, 3), N >= 1, got {theta.shape}, {tau.shape}",
                           argument="rest")
        if not (np.isfinite(theta).all() and np.isfinite(tau).all()):
            raise LogError("theta and tau must be finite", argument="rest")
        object.__setattr__(self, "theta", theta)
        object.__setattr__(self, "tau", tau)


def rest_of(log: Log) -> Rest:
    """The stretches of ``log`` where the arm is still (module constants), each averaged into one
    posture and its holding torque; LogError where it holds none."""
    window = max(1, int(round(0.02 * log.rate)))
    kernel = np.ones(window) / window
    smooth = np.column_stack([np.convolve(log.theta[:, j], kernel, mode="same") for j in range(3)])
    still = (np.abs(np.gradient(smooth, log.t, axis=0)) < REST_SPEED).all(axis=1)
    edges = np.flatnonzero(np.diff(np.concatenate([[0], still.astype(int), [0]])))
    trim = int(round(REST_TRIM * log.rate))
    stretches = [(a + trim, b - trim) for a, b in zip(edges[::2], edges[1::2])
                 if log.t[b - 1] - log.t[a] >= REST_HOLD]
    if not stretches:
        raise LogError(f"no rest in the log: no stretch of {REST_HOLD:g} s where every joint is slower than "
                       f"{REST_SPEED:g} rad/s (hold the arm still at each posture)", argument="log")
    return Rest(np.array([log.theta[a:b].mean(axis=0) for a, b in stretches]),
                np.array([log.tau[a:b].mean(axis=0) for a, b in stretches]))


@dataclasses.dataclass(frozen=True)
class Gravity:
    """The result of ``estimate_gravity``: ``beta`` (the base parameters, the rest postures' fit
    carried by the prior), ``covariance``, ``x`` the physical parameters written (Structure.names)
    and ``written`` their base parameters; ``directions`` (the gravity directions over the
    postures inside the stops) and ``determined`` (how many of them the postures determine);
    ``scale`` (the gravity scale fitted where they determine fewer, else None) and its
    ``scale_sigma``; ``residual`` (3,) N m RMS at the postures; ``predicted`` (3,): the gravity
    uncertainty at CHECK_POSTURES postures (1 sigma share of the gravity RMS per joint);
    ``fewest``: indices of the fewest given postures that determine what they determine;
    ``suggested`` (K, 3) rad: postures to add."""

    beta: np.ndarray
    covariance: np.ndarray
    x: np.ndarray
    written: np.ndarray
    directions: int
    determined: int
    scale: float | None
    scale_sigma: float
    residual: np.ndarray
    predicted: np.ndarray
    fewest: tuple[int, ...]
    suggested: np.ndarray

    def lines(self, postures: int) -> list[str]:
        """What it found, one line each (``postures``: how many it was given)."""
        joints = ", ".join("none (no gravity)" if np.isnan(p) else f"{100 * p:.2g} %" for p in self.predicted)
        lines = [f"gravity from {postures} rest posture(s): they determine {self.determined} of the "
                 f"{self.directions} gravity directions; residual " + ", ".join(f"{r:.3g}" for r in self.residual)
                 + " N m RMS per joint",
                 f"predicted gravity uncertainty at {CHECK_POSTURES} postures inside the stops: {joints} of its RMS "
                 "per joint (1 sigma)"]
        if self.scale is not None:
            lines.append(f"too few postures for the gravity directions: one scale fitted on the model's gravity, "
                         f"{self.scale:.4g} +- {self.scale_sigma:.2g} (every link's mass and moments scaled alike)")
        lines.append(f"the fewest of these postures that determine it: {len(self.fewest)} (rows "
                     + ", ".join(str(k + 1) for k in self.fewest) + ")")
        lines += [f"add a posture near theta = ({', '.join(f'{a:.3f}' for a in theta)}) rad"
                  for theta in self.suggested]
        return lines


def estimate_gravity(rest: Rest, phantom: Phantom, prior_spread: float = priors.SPREAD,
                     prior_weight: float = 1e-3) -> Gravity:
    """Gravity identified from ``rest`` on the configuration of ``phantom`` (its parameters the
    prior, with relative spread ``prior_spread``; module doc). LogError for postures beyond the
    stops' reach; InvalidInputError naming a bad argument."""
    if not isinstance(rest, Rest):
        raise InvalidInputError(f"expected a Rest (rest_of, read_postures), got {rest!r}", argument="rest")
    if not isinstance(phantom, Phantom):
        raise InvalidInputError(f"expected a phantom_pin.Phantom, got {phantom!r}", argument="phantom")
    spread = priors.spread_argument(prior_spread)
    if not np.isfinite(spread):
        raise InvalidInputError("rest postures determine gravity only: the prior holds the rest (a finite spread)",
                                argument="prior_spread")
    structure = General(phantom)
    basis = _directions(structure, phantom)
    beta0, prior = priors.base_prior(structure.matrix, structure.offset, structure.prior, structure.scale, spread)
    phi, known = _gravity(structure, rest.theta)
    a, y = phi @ basis, rest.tau - known
    gamma0, gamma_prior = basis.T @ beta0, basis.T @ prior @ basis
    determined = _rank(a / np.sqrt(np.diag(gamma_prior)))
    scale, scale_sigma = None, 0.0
    if determined == basis.shape[1]:
        gamma, gamma_covariance = _fit(a, y, gamma0, gamma_prior)
    else:
        scale, scale_sigma, gamma, gamma_covariance = _scaled(a, y, gamma0, gamma_prior)
    gain = prior @ basis @ np.linalg.inv(gamma_prior)          # beta | gamma: the prior's regression
    beta = beta0 + gain @ (gamma - gamma0)
    covariance = prior - gain @ basis.T @ prior + gain @ gamma_covariance @ gain.T
    x = _projection(structure, beta, covariance, prior_weight)
    written = structure.matrix @ x + structure.offset
    check = _gravity(structure, sample_postures(phantom.config.limits, CHECK_POSTURES, np.random.default_rng(SEED)))[0]
    size = np.sqrt(((check @ written) ** 2).mean(axis=0))
    size = np.where(size > 1e-9 * size.max(), size, np.nan)          # joint 1 carries no gravity: no share
    sigma = np.sqrt(np.einsum("nip,pq,niq->ni", check @ basis, gamma_covariance, check @ basis))
    residual = np.sqrt(((y - a @ (basis.T @ written)) ** 2).mean(axis=0))
    return Gravity(beta, covariance, x, written, basis.shape[1], determined, scale, scale_sigma, residual,
                   np.sqrt((sigma**2).mean(axis=0)) / size, _fewest(a, gamma_prior, determined),
                   _suggested(structure, phantom, basis, a, gamma_prior))


def _gravity(structure: Structure, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(Phi_g (N, 3, P), the known torques (N, 3; N m)) at rest at the postures ``theta`` (rad)."""
    zero = np.zeros_like(theta)
    return structure.regressor_of(theta, zero, zero, np.zeros((len(theta), 3, 6)))


def _directions(structure: Structure, phantom: Phantom) -> np.ndarray:
    """The base parameters' gravity directions (P, r): the right singular vectors of Phi_g over
    GRAVITY_POSTURES seeded postures inside the stops."""
    phi, _ = _gravity(structure, sample_postures(phantom.config.limits, GRAVITY_POSTURES, np.random.default_rng(SEED)))
    _, sizes, vt = np.linalg.svd(phi.reshape(-1, phi.shape[-1]), full_matrices=False)
    return vt[sizes > RANK_TOLERANCE * sizes[0]].T


def _noise(a: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Each joint's torque noise (3,; N m): the least-squares residual's, pooled over the joints as
    a share of their holding torques' RMS, where the equations the gravity acts in (joint 1's
    never: its axis is vertical) exceed the directions by MIN_DOF; else NOISE_ASSUMED of that
    RMS; never below NOISE_FLOOR of it."""
    acting = np.abs(a).sum(axis=-1) > 0                                   # (N, 3)
    size = np.sqrt((y**2 * acting).sum(axis=0) / np.maximum(acting.sum(axis=0), 1))
    stacked = a[acting]
    solution = np.linalg.lstsq(stacked, y[acting], rcond=None)[0]
    dof = int(acting.sum()) - _rank(stacked)
    share = NOISE_ASSUMED
    if dof >= MIN_DOF:
        residual = (y - a @ solution) * acting / np.where(size > 0, size, 1.0)
        share = float(np.sqrt((residual**2).sum() / dof))
    return np.maximum(share, NOISE_FLOOR) * size


def _fit(a: np.ndarray, y: np.ndarray, gamma0: np.ndarray, prior: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The Gauss-Markov estimate of gamma (its covariance) from y = a gamma + noise (_noise),
    with the prior N(gamma0, prior)."""
    weight = 1.0 / np.maximum(_noise(a, y), 1e-300)
    aw = (a * weight[:, None]).reshape(-1, a.shape[-1])
    inverse = np.linalg.inv(prior)
    covariance = np.linalg.inv(aw.T @ aw + inverse)
    return covariance @ (aw.T @ (y * weight).reshape(-1) + inverse @ gamma0), covariance


def _scaled(a: np.ndarray, y: np.ndarray, gamma0: np.ndarray,
            prior: np.ndarray) -> tuple[float, float, np.ndarray, np.ndarray]:
    """The gravity scale s with y = s (a gamma0) in least squares, its standard deviation, and
    gamma = s gamma0 with its covariance: s's uncertainty along gamma0, and the prior's
    uncertainty of the gravity's shape (its covariance given the direction gamma0), scaled by s:
    the data say nothing of the shape."""
    model = (a @ gamma0).reshape(-1)
    s = float(model @ y.reshape(-1) / (model @ model))
    residual = y.reshape(-1) - s * model
    sigma = float(np.sqrt(residual @ residual / max(model.size - 1, 1) / (model @ model)))
    inverse = np.linalg.inv(prior)
    along = np.outer(gamma0, gamma0 @ inverse) / (gamma0 @ inverse @ gamma0)   # the projection onto gamma0
    shape = (np.eye(len(gamma0)) - along) @ prior @ (np.eye(len(gamma0)) - along).T
    return s, sigma, s * gamma0, sigma**2 * np.outer(gamma0, gamma0) + s**2 * shape


def _projection(structure: Structure, beta: np.ndarray, covariance: np.ndarray, prior_weight: float) -> np.ndarray:
    """The physical parameters nearest to ``beta`` in the metric of ``covariance`` (physical.nearest)."""
    return structure.nearest(beta, metric_root(covariance, 1e-12), prior_weight)


def _fewest(a: np.ndarray, prior: np.ndarray, rank: int) -> tuple[int, ...]:
    """The fewest rows of the rest postures (greedy) whose gravity regressor reaches ``rank``."""
    scaled = a / np.sqrt(np.diag(prior))
    chosen: list[int] = []
    while len(chosen) < len(a) and _rank(scaled[chosen]) < rank:
        chosen.append(max((k for k in range(len(a)) if k not in chosen),
                          key=lambda k: _smallest(scaled[chosen + [k]], rank)))
    return tuple(sorted(chosen))


def _suggested(structure: Structure, phantom: Phantom, basis: np.ndarray, a: np.ndarray,
               prior: np.ndarray) -> np.ndarray:
    """SUGGESTED postures inside the stops (of seeded candidates) that most raise the smallest
    singular value of the gravity regressor ``a`` (N, 3, r; in the directions ``basis``) scaled
    by the prior's spread, each chosen after the ones before."""
    candidates = sample_postures(phantom.config.limits, 200, np.random.default_rng(SEED + 1), margin=0.05)
    rows = _gravity(structure, candidates)[0] @ basis / np.sqrt(np.diag(prior))
    stacked, chosen = a / np.sqrt(np.diag(prior)), list[int]()
    for _ in range(SUGGESTED):
        k = max((k for k in range(len(candidates)) if k not in chosen),
                key=lambda k: _smallest(np.concatenate([stacked, rows[k:k + 1]]), basis.shape[1]))
        stacked, chosen = np.concatenate([stacked, rows[k:k + 1]]), chosen + [k]
    return candidates[chosen]


def _rank(rows: np.ndarray) -> int:
    """The number of singular values of the stacked rows above RANK_TOLERANCE of the largest
    (times 1e3: measured torques carry noise, not rounding)."""
    if not len(rows):
        return 0
    sizes = np.linalg.svd(rows.reshape(-1, rows.shape[-1]), compute_uv=False)
    return int((sizes > 1e3 * RANK_TOLERANCE * sizes[0]).sum())


def _smallest(rows: np.ndarray, rank: int) -> float:
    """The rank-th singular value of the stacked rows (0 where they reach fewer)."""
    sizes = np.linalg.svd(rows.reshape(-1, rows.shape[-1]), compute_uv=False)
    return float(sizes[rank - 1]) if len(sizes) >= rank else 0.0
