"""The prior of an identification: the base parameters of the configuration the user passes (the
shipped model, their own folder, or an earlier overlay) and how far the device may lie from them.

The estimate (estimation.estimate) is the Gauss-Markov (Bayesian linear) one with this prior as
its mean and covariance,

    beta = argmin |W (y - Phi beta)|^2 / s^2 + (beta - beta_0)^T P^-1 (beta - beta_0),

so that what the log excites comes from the log, what it does not from the prior, and the
change between the two follows the information of each (no weight tuned by hand). It is the
ordinary weighted least-squares estimate plus P^-1: where the log's information Phi_w^T Phi_w
/ s^2 dwarfs P^-1 (an excitation trajectory: 1e6-1e12 times, direction by direction) the two
agree to far below their standard deviations, and where it vanishes the estimate is beta_0.

Chosen over the log-det (Bregman) divergence between the links' pseudo-inertias and the prior's
(Lee, Wensing and Park 2020) because it acts on the base parameters, the only ones the torques
determine: a closed form, the covariance the predicted torque uncertainty carries
(prediction.py), and a weight that is the stated P against the log's own noise s^2, nothing to
tune; the physical projection that follows (physical.py) keeps the log-det barrier.

P is stated in the physical parameters x (structures.Structure.names) and carried to the base
parameters, P = M diag((SPREAD scale)^2) M^T (beta = M x + offset): each entry of x independent,
with standard deviation SPREAD (30 %) of its typical size ``scale`` (structures: for a body, m,
m r and m r^2 with m its mass and r its radius of gyration about the link origin, so that a
product of inertia or an off-axis first moment is allowed 30 % of the body's size, not 30 % of
a value that may be zero; the rotor inertia and each friction coefficient, 30 % of the model's
value, or of structures.FRICTION_FLOOR of the joint's torque limit where the model has none).
30 %: a model of the same design built by another lab differs by this much (the CAD
masses against the report's: 8-25 % per link, docs/cad.md; friction laws between devices of one
model: 20-40 %), and a prior tighter than the truth's distance would bias the excited
directions, a looser one only lets the log decide a little more.
"""

from __future__ import annotations

import numpy as np

from phantom_pin.exceptions import InvalidInputError

#: The prior's relative standard deviation of every physical parameter (module doc).
SPREAD = 0.3
#: The largest finite spread: beyond it the prior no longer moves the fit (at 1e6 it equals the
#: log alone's to 1e-12), and its variances, (spread scale)^2, overflow from about 1e150.
MAX_SPREAD = 1e6


def spread_argument(value: object) -> float:
    """``value`` as a prior spread: a number > 0 and at most MAX_SPREAD, inf for none (the log
    alone); InvalidInputError naming ``prior_spread`` otherwise."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or np.isnan(value) or value <= 0:
        raise InvalidInputError(f"expected a relative standard deviation > 0 (inf: no prior), got {value!r}",
                                argument="prior_spread")
    if MAX_SPREAD < value < np.inf:
        raise InvalidInputError(f"{value!r} is beyond {MAX_SPREAD:g}, where the prior no longer counts; give inf "
                                "for no prior", argument="prior_spread")
    return float(value)


def base_prior(matrix: np.ndarray, offset: np.ndarray, x: np.ndarray, scale: np.ndarray,
               spread: float = SPREAD) -> tuple[np.ndarray, np.ndarray]:
    """(beta_0, P): the prior's base parameters, M x + offset, and their covariance M diag((spread
    scale)^2) M^T (module doc), in the base parameters' units squared; ``spread`` finite (an
    infinite one is no prior: estimation.estimate then fits the log alone)."""
    beta0 = np.asarray(matrix) @ np.asarray(x, float) + np.asarray(offset, float)
    covariance = (np.asarray(matrix) * (spread * np.asarray(scale, float)) ** 2) @ np.asarray(matrix).T
    return beta0, covariance


def typical(matrix: np.ndarray, scale: np.ndarray) -> np.ndarray:
    """The typical size of each base parameter, |M| scale: the prior's spread is a share of it."""
    return np.abs(np.asarray(matrix)) @ np.asarray(scale, float)
