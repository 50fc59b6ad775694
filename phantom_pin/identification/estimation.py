"""Estimation: zero-phase filtering, weighted least squares of the base parameters and the
friction, and the nearest physically consistent report parameters.

1. The positions (rad) are low-passed by a Butterworth filter run forwards and backwards
   (scipy.signal.filtfilt, no phase lag) and differentiated by central differences into
   dtheta (rad/s) and ddtheta (rad/s^2); the torques get the same filter (parallel
   filtering), so that both sides of tau = Phi beta see the same distortion. The filter's
   edge transients are cut and the samples decimated to about 5 times the cutoff.
2. beta (constants.NAMES + friction) by ordinary least squares, then weighted by the inverse
   residual standard deviation of each joint (Gauss-Markov); covariance
   s^2 (Phi_w^T Phi_w)^-1.
3. physical.nearest: the report parameters x whose constants C x are nearest to beta in the
   covariance's metric, with every link physically consistent.
"""

from __future__ import annotations

import dataclasses
from typing import Callable

import numpy as np
import scipy.signal

from phantom_pin.dynamics.model import Phantom
from phantom_pin.exceptions import InvalidInputError
from phantom_pin.identification import constants, parameterization, physical
from phantom_pin.identification.base import Structured, base_parameters
from phantom_pin.identification.io import Log, LogError
from phantom_pin.identification.regressor import Regressor

#: Largest accepted condition number of the base regressor (columns scaled to unit norm).
MAX_CONDITION = 1e3
#: Filter order and edge cut (s).
FILTER_ORDER, EDGE = 4, 0.25


@dataclasses.dataclass(frozen=True)
class Fit:
    """Result of ``estimate``: beta (14,) and its standard deviations, the residual RMS per
    joint (N m) and the RMS torque (N m), the condition number, the number of samples, the
    consistent report parameters x (20,) and their constants C x (8,); and, as a check of the
    report's structure, the residual RMS per joint (N m) and the rank of the general
    rigid-body model (every standard parameter of every body: ``general_rms``, ``general_rank``)."""

    beta: np.ndarray
    sigma: np.ndarray
    rms: np.ndarray
    torque_rms: np.ndarray
    condition: float
    samples: int
    x: np.ndarray
    constants: np.ndarray
    general_rms: np.ndarray
    general_rank: int


def filtered(log: Log, cutoff: float) -> tuple[np.ndarray, ...]:
    """(theta, dtheta, ddtheta, tau), filtered at ``cutoff`` (Hz), edges cut, decimated."""
    rate = log.rate
    if not 0 < cutoff < rate / 2:
        raise LogError(f"cutoff: {cutoff} Hz must lie between 0 and half the rate ({rate / 2:.4g} Hz)")
    sos = scipy.signal.butter(FILTER_ORDER, cutoff, fs=rate, output="sos")
    theta = scipy.signal.sosfiltfilt(sos, log.theta, axis=0)
    tau = scipy.signal.sosfiltfilt(sos, log.tau, axis=0)
    dt = 1.0 / rate
    dtheta = np.gradient(theta, dt, axis=0)
    ddtheta = np.gradient(dtheta, dt, axis=0)
    edge = int(np.ceil(EDGE * rate))
    step = max(1, int(rate / (5 * cutoff)))
    keep = slice(edge, len(log.t) - edge, step)
    return theta[keep], dtheta[keep], ddtheta[keep], tau[keep]


def base_regressor(structured: Structured, theta, dtheta, ddtheta) -> tuple[np.ndarray, np.ndarray]:
    """(Phi (N, 3, 14), tau_0 (N, 3)) in beta = (constants, friction), from Pinocchio's regressor:
    Phi = [Phi_x C^+, Phi_friction] (Phi_x = Y A, exact because Phi_x = Phi_constants C)."""
    phi_x, tau0 = structured(theta, dtheta, ddtheta)
    n = len(parameterization.NAMES)
    pseudo = np.linalg.pinv(constants.constants_matrix(structured.description))
    return np.concatenate([phi_x[..., :n] @ pseudo, phi_x[..., n:]], axis=-1), tau0


def estimate(log: Log, phantom: Phantom, cutoff: float = 20.0, prior_weight: float = 1e-3,
             progress: Callable[[float], None] | None = None) -> Fit:
    """Identify beta and the nearest consistent report parameters from a device log, for the
    configuration of ``phantom`` (its report numbers are the prior, its friction law the
    friction columns). Everything it needs is computed once per Description (cached on it).
    ``progress(share)`` is called as its stages end (filtering, the regressor, the fits)."""
    def stage(share: float) -> None:
        if progress is not None:
            progress(share)

    if not isinstance(log, Log):
        raise InvalidInputError(f"log: expected a phantom_pin.identification.io.Log (read_log), got {log!r}")
    if not isinstance(phantom, Phantom):
        raise InvalidInputError(f"phantom: expected a phantom_pin.Phantom, got {phantom!r}")
    for name, value in (("cutoff", cutoff), ("prior_weight", prior_weight)):
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not np.isfinite(value) or value <= 0:
            raise InvalidInputError(f"{name}: expected a finite number > 0, got {value!r}")

    theta, dtheta, ddtheta, tau = filtered(log, cutoff)
    stage(0.1)
    if len(theta) < 50:
        raise LogError(f"too short: {len(theta)} samples after filtering (need 50)")
    structured = Structured(Regressor(phantom))
    phi, tau0 = base_regressor(structured, theta, dtheta, ddtheta)
    stage(0.4)
    p = phi.shape[-1]
    stacked, y = phi.reshape(-1, p), (tau - tau0).reshape(-1)
    norms = np.linalg.norm(stacked, axis=0)
    condition = float(np.linalg.cond(stacked / np.where(norms > 0, norms, 1.0)))
    if not condition <= MAX_CONDITION:
        raise LogError(f"not exciting enough: the base regressor's condition number is {condition:.3g} "
                       f"(at most {MAX_CONDITION:.0e}); log an excitation trajectory (phantom-pin excite)")
    beta = np.linalg.lstsq(stacked, y, rcond=None)[0]
    residual = (y - stacked @ beta).reshape(-1, 3)
    joint_sigma = np.sqrt((residual**2).sum(axis=0) / (len(residual) - p / 3))
    weight = np.tile(1.0 / joint_sigma, len(theta))
    weighted, yw = stacked * weight[:, None], y * weight
    beta, *_ = np.linalg.lstsq(weighted, yw, rcond=None)
    rw = yw - weighted @ beta
    s2 = rw @ rw / (len(yw) - p)
    covariance = s2 * np.linalg.inv(weighted.T @ weighted)
    residual = (y - stacked @ beta).reshape(-1, 3)
    c = constants.constants_matrix(phantom.description)
    n = len(constants.NAMES)
    info = np.linalg.inv(covariance[:n, :n])
    root = np.linalg.cholesky(info).T                       # root^T root = covariance^-1
    affine, offset = structured.affine, structured.offset
    prior = parameterization.report_vector(phantom.config)
    stage(0.5)
    x = physical.nearest(beta[:n], root, c, prior, affine, offset, phantom.config, prior_weight)
    stage(0.7)
    general = structured.regressor.stacked(theta, dtheta, ddtheta)
    base = base_parameters(general, structured.regressor.names)
    independent = general[:, list(base.independent)]
    fitted = independent @ np.linalg.lstsq(independent, tau.reshape(-1), rcond=None)[0]
    general_rms = np.sqrt(((tau.reshape(-1) - fitted).reshape(-1, 3) ** 2).mean(axis=0))
    return Fit(beta, np.sqrt(np.diag(covariance)), np.sqrt((residual**2).mean(axis=0)),
               np.sqrt(((tau - tau0)**2).mean(axis=0)), condition, len(theta), x, c @ x,
               general_rms, base.rank)
