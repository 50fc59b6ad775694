"""identification.fitting.least_squares: the weighted fit against numpy.linalg.lstsq and the
Gauss-Markov formula, the covariance helpers against their definitions (inverse, Schur
complement), the joints' torque gains recovered from a log scaled by known gains."""

import numpy as np
import pytest

from phantom_pin.identification.fitting import least_squares


def _problem(seed, n=200, p=5, noise=(0.1, 0.2, 0.05)):
    rng = np.random.default_rng(seed)
    phi = rng.normal(size=(n, 3, p))
    truth = rng.normal(size=p)
    return phi, truth, phi @ truth + rng.normal(size=(n, 3)) * noise


def test_the_estimate_with_the_prior_is_the_gauss_markov_formula():
    """least_squares.fit with a prior (beta_0, P) against the textbook formula on a seeded problem,
    beta = (A + P^-1)^-1 (Phi_w^T y_w / s^2 + P^-1 beta_0), covariance (A + P^-1)^-1, A the log's
    information (its own output, checked as Phi_w^T Phi_w / s^2 by the log alone's covariance):
    within 1e-9; a prior 1e6 times looser gives the log alone's beta within 1e-6 of its standard
    deviations, one 1e-6 times tighter the prior's within 1e-6 of the prior's."""
    rng = np.random.default_rng(2)
    phi = rng.normal(size=(200, 3, 5))
    truth = rng.normal(size=5)
    y = phi @ truth + rng.normal(size=(200, 3)) * [0.1, 0.2, 0.05]
    root = rng.normal(size=(5, 5))
    spread, beta0 = root @ root.T * 0.01, truth + rng.normal(size=5) * 0.3
    beta, covariance, _, weight, information, alone = least_squares.fit(phi, y, prior=(beta0, spread))
    inverse = np.linalg.inv(spread)
    log_covariance = least_squares.fit(phi, y)[1]
    np.testing.assert_allclose(np.linalg.inv(log_covariance), information, rtol=1e-9)
    expected = np.linalg.solve(information + inverse, information @ alone + inverse @ beta0)
    np.testing.assert_allclose(beta, expected, rtol=1e-9)
    np.testing.assert_allclose(covariance, np.linalg.inv(information + inverse), rtol=1e-9, atol=1e-15)
    sigma = np.sqrt(np.diag(log_covariance))
    loose = least_squares.fit(phi, y, prior=(beta0, spread * 1e12))[0]
    assert (np.abs(loose - alone) < 1e-6 * sigma).all()
    tight = least_squares.fit(phi, y, prior=(beta0, spread * 1e-12))[0]
    np.testing.assert_allclose(tight, beta0, rtol=1e-6)


def test_the_log_alones_covariance_is_infinite_where_it_sees_nothing():
    """least_squares.inverse_information: the inverse of a nonsingular information (units 1e-12 to
    1e6 apart) within 1e-9, in the units that balance its diagonal; a singular one gives inf on
    the variance of each parameter its null direction (a + b) involves, the inverse elsewhere."""
    rng = np.random.default_rng(4)
    root = rng.normal(size=(3, 3)) * [1e3, 1.0, 1e-6]
    information = root.T @ root
    d = np.sqrt(np.diag(information))                  # compared in the units that balance it
    scaled = (least_squares.inverse_information(information) * np.outer(d, d)) @ (information / np.outer(d, d))
    np.testing.assert_allclose(scaled, np.eye(3), atol=1e-9)
    v = np.array([[1, 1, 0], [1, -1, 0], [0, 0, np.sqrt(2)]]) / np.sqrt(2)
    singular = v.T @ np.diag([0.0, 4.0, 100.0]) @ v
    variance = np.diag(least_squares.inverse_information(singular))
    assert np.isinf(variance[:2]).all() and variance[2] == pytest.approx(0.01, rel=1e-12)


def test_the_fit_is_the_two_pass_weighted_least_squares():
    """Without a prior: beta is numpy.linalg.lstsq's on the equations weighted by each joint's
    1 / residual standard deviation of the unweighted fit (N - P/3 degrees of freedom per
    joint), within 1e-12; the covariance is s^2 (Phi_w^T Phi_w)^-1 within 1e-9; the residual is
    y - Phi beta, and 0 on the equations not ``moving``."""
    phi, _, y = _problem(3)
    moving = np.ones(y.shape, bool)
    moving[:20, 1] = False
    beta, covariance, residual, weight, _, alone = least_squares.fit(phi, y, moving)
    m = moving[..., None]
    ordinary = np.linalg.lstsq((phi * m).reshape(-1, 5), (y * moving).reshape(-1), rcond=None)[0]
    r = (y - phi @ ordinary) * moving
    sigma = np.sqrt((r**2).sum(axis=0) / (moving.sum(axis=0) - 5 / 3))
    np.testing.assert_allclose(weight, 1 / sigma, rtol=1e-12)
    a, b = (phi * m / sigma[:, None]).reshape(-1, 5), (y * moving / sigma).reshape(-1)
    expected = np.linalg.lstsq(a, b, rcond=None)[0]
    np.testing.assert_allclose(beta, expected, rtol=1e-12)
    np.testing.assert_array_equal(beta, alone)
    s2 = (b - a @ expected) @ (b - a @ expected) / (moving.sum() - 5)
    np.testing.assert_allclose(covariance, s2 * np.linalg.inv(a.T @ a), rtol=1e-9)
    np.testing.assert_allclose(residual, (y - phi @ expected) * moving, atol=1e-12)
    assert (residual[:20, 1] == 0).all()


def test_rms_and_the_condition_number_by_hand():
    """rms over the moving equations only (a joint with none: 0, not NaN); condition_number
    after scaling the columns to unit norm: diag(1, 1e6)'s is 1; [[1, 1], [0, 1]]'s, whatever
    its columns' scale, that of unit columns (1, 0) and (1, 1)/sqrt(2): Phi^T Phi has the
    eigenvalues 1 +- 1/sqrt(2), so sqrt((1 + 1/sqrt(2)) / (1 - 1/sqrt(2))) = 1 + sqrt(2)."""
    residual = np.array([[3.0, 1.0, 2.0], [4.0, 1.0, 2.0]])
    moving = np.array([[True, True, False], [True, False, False]])
    np.testing.assert_allclose(least_squares.rms(residual, moving), [np.sqrt(12.5), 1.0, 0.0], rtol=1e-15)
    np.testing.assert_allclose(least_squares.rms(residual), [np.sqrt(12.5), 1.0, 2.0], rtol=1e-15)
    assert least_squares.condition_number(np.diag([1.0, 1e6])) == pytest.approx(1.0, rel=1e-12)
    for scale in (1.0, 1e-8, 1e5):
        skew = np.array([[1.0, 1.0], [0.0, 1.0]]) * [1.0, scale]
        assert least_squares.condition_number(skew) == pytest.approx(1 + np.sqrt(2), rel=1e-12)


def test_the_metric_root_and_the_marginal_information():
    """metric_root: W^T W = covariance^-1 within 1e-9 (a seeded covariance, units 1e-6 to 1e3
    apart); marginal: the Schur complement equals the inverse of the covariance's leading block
    within 1e-9, and the whole information when nothing else is estimated."""
    rng = np.random.default_rng(5)
    root = rng.normal(size=(4, 4)) * [1e3, 1.0, 1e-3, 1e-6]
    covariance = root.T @ root
    w = least_squares.metric_root(covariance)
    d = np.sqrt(np.diag(covariance))
    np.testing.assert_allclose((w.T @ w) * np.outer(d, d), np.linalg.inv(covariance / np.outer(d, d)),
                               rtol=1e-9, atol=1e-9)
    information = np.linalg.inv(covariance / np.outer(d, d))
    block = np.linalg.inv((covariance / np.outer(d, d))[:2, :2])
    np.testing.assert_allclose(least_squares.marginal(information, 2), block, rtol=1e-9)
    assert least_squares.marginal(information, 4) is information


def test_the_gains_are_recovered_from_a_log_scaled_by_them():
    """solve_gains on a log whose joints 2 and 3 were logged at 1 / 1.05 and 1 / 0.9 of joint
    1's scale (tau_j = (Phi_j beta + tau0_j) / g_j, 0.1 % noise): the gains within 5 of their
    standard deviations and 1e-3; beta within 1e-3 of the truth; with no free joint the gains
    are exactly 1 and beta is the plain fit's."""
    phi, truth, _ = _problem(6, n=400, noise=(0, 0, 0))
    rng = np.random.default_rng(7)
    tau0 = rng.normal(size=(400, 3)) * 0.1
    gains = np.array([1.0, 1.05, 0.9])
    clean = phi @ truth + tau0
    tau = clean / gains + rng.normal(size=clean.shape) * 1e-3 * clean.std(axis=0)
    moving = np.ones(tau.shape, bool)
    beta, *_, (found, sigma) = least_squares.solve_gains(phi, tau, tau0, moving, None, (1, 2))
    assert found[0] == 1 and sigma[0] == 0
    assert (np.abs(found - gains) < 5 * sigma + 1e-12).all() and np.abs(found - gains).max() < 1e-3
    np.testing.assert_allclose(beta, truth, atol=1e-3)
    plain, *_, (ones, _) = least_squares.solve_gains(phi, tau, tau0, moving, None, ())
    np.testing.assert_array_equal(ones, np.ones(3))
    np.testing.assert_allclose(plain, least_squares.fit(phi, tau - tau0, moving)[0], rtol=1e-12)
