"""Physical consistency of identified parameters: every link passes the one physical check of a
link (phantom_pin.inertial.problem), the rotor inertia is positive; and the nearest
consistent report parameters to an estimate.
"""

from __future__ import annotations

import numpy as np
import scipy.optimize

from phantom_pin.config import Config
from phantom_pin.identification import parameterization
from phantom_pin.inertial import problem
from phantom_pin.report.parameters import links

#: How far inside the triangle inequality (a share of the largest moment) SLSQP aims. It is
#: not a tolerance of the law: ``consistent`` decides with the exact links and the one check
#: (phantom_pin.inertial.problem); this margin only covers the affine map's rounding (up to
#: about 1e-12 of the largest parameter), so that the optimiser's answer passes that check.
_AIM = 1e-9


def body_margins(pi_inertial: np.ndarray) -> np.ndarray:
    """(n_bodies, 4): mass (kg), smallest principal moment at the COM, the triangle slack
    lambda1 + lambda2 - lambda3 and the largest moment lambda3 (kg m^2, ascending) of each body,
    from standard parameters [m, h, I_origin] (Pinocchio's order)."""
    out = []
    for m, hx, hy, hz, ixx, ixy, iyy, ixz, iyz, izz in np.asarray(pi_inertial).reshape(-1, 10):
        h = np.array([hx, hy, hz])
        origin = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
        com = origin - (h @ h * np.eye(3) - np.outer(h, h)) / m if m > 0 else origin
        moments = np.linalg.eigvalsh(com)
        out.append([m, moments[0], moments[0] + moments[1] - moments[2], moments[2]])
    return np.array(out)


def _constraints(x: np.ndarray, affine: np.ndarray, offset: np.ndarray) -> np.ndarray:
    """The smooth margins of the physical check (>= 0 where it holds, scaled for SLSQP)."""
    pi = affine @ x + offset
    margins = body_margins(pi[:-3])
    return np.concatenate([margins[:, 0], margins[:, 1] * 1e4, (margins[:, 2] - _AIM * margins[:, 3]) * 1e4,
                           [x[parameterization.ROTOR] * 1e6]])


def consistent(x: np.ndarray, config: Config) -> bool:
    """True if the report parameters ``x`` give links (report.parameters.links, as describe()
    computes them from the written overlay) that all pass phantom_pin.inertial.problem, with
    positive masses and rotor inertia x[ROTOR] (zero, without public motor data: Actuation.rotor)."""
    x = np.asarray(x, float)
    rotor = x[parameterization.ROTOR]
    if not ((rotor > 0 if config.actuation.motor else rotor == 0) and (x[list(parameterization.MASSES)] > 0).all()):
        return False
    linked = links(parameterization.report_parameters(x, config), config.unprinted, float(rotor),
                   config.actuation.rotor[1])
    return all(problem(link) is None for link in linked.values())


def nearest(target: np.ndarray, weights: np.ndarray, constants_matrix: np.ndarray,
            prior: np.ndarray, affine: np.ndarray, offset: np.ndarray, config: Config,
            prior_weight: float = 1e-3) -> np.ndarray:
    """The report parameters x nearest to the estimated constants ``target``:
    minimise |W (C x - target)|^2 + prior_weight^2 |(x - prior) / prior|^2 subject to
    every tree body's mass, inertia and triangle conditions and J > 0. The unconstrained
    optimum if it is consistent; else the farthest consistent point from the prior towards it,
    refined by SLSQP: always consistent. ``weights`` W is
    a matrix with W^T W = the inverse covariance of ``target`` (or a vector: its diagonal).
    The prior (the report's values) fixes the directions the data cannot see; its weight is
    small so that it does not move the identifiable constants measurably."""
    scale = np.where(prior != 0, np.abs(prior), 1.0)  # J = 0 without public motor data
    weights = np.diag(weights) if np.ndim(weights) == 1 else np.asarray(weights)

    def residual(z):
        x = z * scale
        return np.concatenate([weights @ (constants_matrix @ x - target), prior_weight * (z - prior / scale)])

    def cost(z):
        r = residual(z)
        return 0.5 * r @ r

    def gradient(z):
        jac = np.vstack([weights @ constants_matrix * scale, prior_weight * np.eye(len(z))])
        return jac.T @ residual(z)

    z0 = prior / scale
    unconstrained = scipy.optimize.least_squares(residual, z0, method="lm").x
    if consistent(unconstrained * scale, config):
        return unconstrained * scale
    # the farthest consistent point on the segment from the (consistent) prior to the
    # unconstrained optimum, by bisection: always available, and SLSQP's start
    low, high = 0.0, 1.0
    for _ in range(60):
        middle = (low + high) / 2
        if consistent((z0 + middle * (unconstrained - z0)) * scale, config):
            low = middle
        else:
            high = middle
    fallback = z0 + low * (unconstrained - z0)
    norm = max(cost(fallback), 1e-300)
    result = scipy.optimize.minimize(
        lambda z: cost(z) / norm, fallback, jac=lambda z: gradient(z) / norm, method="SLSQP",
        constraints=[{"type": "ineq", "fun": lambda z: _constraints(z * scale, affine, offset)}],
        options={"maxiter": 500, "ftol": 1e-12})
    if consistent(result.x * scale, config) and cost(result.x) < cost(fallback):
        return result.x * scale
    return fallback * scale
