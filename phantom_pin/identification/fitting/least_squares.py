"""Weighted least squares of the base parameters, with the prior and the joints' torque gains.

beta by ordinary least squares, then weighted by the inverse residual standard deviation of
each joint (Gauss-Markov): the log's information Phi_w^T Phi_w / s^2. With the prior (prior.py:
the configuration's own base parameters as the mean, a stated covariance P), the Gauss-Markov
estimate with that prior: covariance (Phi_w^T Phi_w / s^2 + P^-1)^-1, equal to the log alone's
s^2 (Phi_w^T Phi_w)^-1 where the log excites everything, the prior's where it excites nothing.

The joints' torque gains (``solve_gains``): each joint's torque gain relative to joint 1 is
estimated with beta (a prior of 1 +- GAIN_SPREAD): the log's tau_j times g_j is the joint's
torque in joint 1's scale (a torque constant, amplifier gain or transmission ratio off on one
joint). Every link's parameters appear in several joints' equations (joint 1's holds every
link), so one joint's scale against the others is in the log; the overall scale is not (all
torques and all parameters scaled alike fit equally), hence joint 1 as the reference.
"""

from __future__ import annotations

import numpy as np

#: The prior's standard deviation of each joint's torque gain relative to joint 1: a torque
#: constant or amplifier gain is specified to a few percent, a transmission ratio misread (11.2
#: for 11.6) is 3.5 % off; the log decides (excite's trajectory: +-0.002-0.1 %; a lab's 60 s sum
#: of sines, which moves joint 1 little: +-0.5 %).
GAIN_SPREAD = 0.05
#: Gauss-Newton steps of the gains at most, and the change of a gain's inverse that ends them.
GAIN_ITERATIONS, GAIN_TOLERANCE = 20, 1e-10


def rms(residual: np.ndarray, moving: np.ndarray | None = None) -> np.ndarray:
    """RMS per joint (N, 3) -> (3,) over the equations ``moving`` (all by default)."""
    moving = np.ones(residual.shape, bool) if moving is None else moving
    return np.sqrt((residual**2 * moving).sum(axis=0) / np.maximum(moving.sum(axis=0), 1))


def condition_number(phi: np.ndarray) -> float:
    """Condition number of a stacked base regressor (N, P) after scaling its columns to unit norm
    (a diagnostic of the excitation and of a fit: the fit is judged by its predicted torques)."""
    norms = np.linalg.norm(phi, axis=0)
    return float(np.linalg.cond(phi / np.where(norms > 0, norms, 1.0)))


def fit(phi: np.ndarray, y: np.ndarray, moving: np.ndarray | None = None,
        prior: tuple[np.ndarray, np.ndarray] | None = None,
        measured: np.ndarray | None = None) -> tuple[np.ndarray, ...]:
    """Weighted least squares of y (N, 3; N m) on phi (N, 3, P) over the equations ``moving``
    (N, 3; all by default): (beta, covariance, residual (N, 3; 0 where not fitted), joint
    weights (3,), the log's information Phi_w^T Phi_w / s^2, the log alone's beta), each joint
    weighted by 1 / its residual standard deviation. With ``prior`` (beta_0, P), the
    Gauss-Markov estimate with that prior (module doc), solved in the base parameters scaled by
    the prior's standard deviations (a singular value decomposition: the log alone may leave
    directions unconstrained). ``measured`` (N, 3, P): the regressor the residuals (and so the
    weights and the noise's variance) are measured with, where ``phi`` is its projection on
    instruments (instruments.py: two-stage least squares); ``phi`` by default."""
    import scipy.linalg  # here: 0.17 s that every command line start paid

    p = phi.shape[-1]
    moving = np.ones(y.shape, bool) if moving is None else moving
    phi, y = phi * moving[..., None], y * moving
    measured = phi if measured is None else measured * moving[..., None]
    stacked = phi.reshape(-1, p)
    beta = np.linalg.lstsq(stacked, y.reshape(-1), rcond=None)[0]
    residual = y - measured @ beta
    joint_sigma = np.sqrt((residual**2).sum(axis=0) / np.maximum(moving.sum(axis=0) - p / 3, 1))
    weight = 1.0 / np.maximum(joint_sigma, 1e-300)
    weighted, yw = (phi * weight[:, None]).reshape(-1, p), (y * weight).reshape(-1)
    beta = log_beta = np.linalg.lstsq(weighted, yw, rcond=None)[0]
    rw = yw - (measured * weight[:, None]).reshape(-1, p) @ beta
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
    return beta, covariance, y - measured @ beta, weight, information, log_beta


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


def metric_root(covariance: np.ndarray, relative_floor: float = 0.0) -> np.ndarray:
    """A root W with W^T W = covariance^-1 (P, P), from the eigenvectors of the correlation (no
    Cholesky: it may be singular to rounding), its eigenvalues floored at ``relative_floor`` of
    the largest (and 1e-300); the standard deviations must be finite."""
    sigma = np.sqrt(np.diag(covariance))
    values, vectors = np.linalg.eigh(covariance / np.outer(sigma, sigma))
    return (vectors / np.sqrt(np.maximum(values, max(1e-300, relative_floor * values.max())))).T / sigma


def marginal(information: np.ndarray, p: int) -> np.ndarray:
    """The information of the first ``p`` parameters with the others estimated alongside: the
    Schur complement of the others' block (their covariance block's inverse)."""
    if information.shape[0] == p:
        return information
    return information[:p, :p] - information[:p, p:] @ np.linalg.solve(information[p:, p:], information[p:, :p])


def solve_gains(phi: np.ndarray, tau: np.ndarray, tau0: np.ndarray, moving: np.ndarray,
                prior: tuple[np.ndarray, np.ndarray] | None, free: tuple[int, ...],
                measured: np.ndarray | None = None) -> tuple:
    """The estimate of beta with the torque gains of the joints ``free`` (of 1, 2; the others
    1): tau_j = (Phi_j beta + tau0_j) / g_j (module doc) solved by Gauss-Newton in beta and the
    inverse gains, linear about the last estimate, the inverse gains' columns being the model's
    torques: free of the log's noise (its own torques there would let a smaller inverse gain
    shrink the residual, biasing the gains). ``phi`` (N, 3, P) and ``tau``, ``tau0`` (N, 3; N m)
    the regressor, the logged and the known torques, ``prior`` (beta_0, P) or None. Returns
    (beta, covariance, information (of beta and the free inverse gains), the log alone's beta
    and residual RMS per joint in joint 1's scale (N m), (gains (3,), standard deviations (3,))).
    ``measured``: the regressor the residuals are measured with where ``phi`` is its projection
    on instruments (``fit``); the gains' columns are then the instruments' torques."""
    import scipy.linalg

    p, scale = phi.shape[-1], np.ones(3)
    measured = phi if measured is None else measured
    # where to start: the gains at 1 (with none free, the loop's one pass is that fit: not done twice)
    beta = fit(phi, (tau - tau0) * moving, moving, prior, measured)[0] if free else np.zeros(p)
    if prior is not None:
        prior = (np.concatenate([prior[0], np.zeros(len(free))]),
                 scipy.linalg.block_diag(prior[1], GAIN_SPREAD**2 * np.eye(len(free))))
    for _ in range(GAIN_ITERATIONS):
        predicted = (phi @ beta + tau0) * moving
        columns = np.zeros((*tau.shape, len(free)))
        for k, j in enumerate(free):
            columns[:, j, k] = predicted[:, j]
        system = np.concatenate([phi * scale[:, None], columns], axis=-1)
        residual_system = np.concatenate([measured * scale[:, None], columns], axis=-1)
        rhs = (tau - scale * tau0) * moving
        if prior is not None:         # the inverse gains' prior mean is 1: their change's, 1 - scale
            prior = (np.concatenate([prior[0][:p], 1.0 - scale[list(free)]]), prior[1])
        solution, covariance, _, _, information, log_beta = fit(system, rhs, moving, prior, residual_system)
        beta, change = solution[:p], solution[p:]
        scale[list(free)] += change
        if not free or np.abs(change).max() <= GAIN_TOLERANCE:
            break
    log_rms = rms(rhs - residual_system @ log_beta, moving) / scale
    sigma = np.zeros(3)
    sigma[list(free)] = np.sqrt(np.diag(covariance)[p:]) / scale[list(free)] ** 2
    return beta, covariance, information, log_beta, log_rms, (1.0 / scale, sigma)
