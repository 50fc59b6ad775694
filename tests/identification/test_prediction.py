"""identification.prediction against laws: the torques' standard deviation against a seeded
Monte Carlo of the parameters, and the poorly excited directions of a known information matrix."""

import numpy as np

from phantom_pin.identification import prediction


def test_the_torque_uncertainty_is_the_spread_of_sampled_parameters():
    """sqrt(diag(Phi C Phi^T)) against the standard deviation of Phi beta over 40000 seeded draws
    of beta ~ N(0, C), for a correlated C: within 3 % (the draws' standard error: 0.35 %)."""
    rng = np.random.default_rng(5)
    phi = rng.normal(size=(4, 3, 6))
    root = rng.normal(size=(6, 6))
    covariance = root @ root.T
    draws = rng.multivariate_normal(np.zeros(6), covariance, 40000)
    sampled = (phi @ draws.T).std(axis=-1)
    np.testing.assert_allclose(prediction.torque_sigma(phi, covariance), sampled, rtol=0.03)


def test_the_poorly_excited_directions_are_named_by_their_parameters():
    """An information matrix with known eigenvectors: (a + b) / sqrt 2 seen with standard deviation
    4 (400 % of the unit sizes), c with 0.5 (50 %), (a - b) / sqrt 2 with 0.01 (1 %, well excited):
    the first two named, most uncertain first; a direction unseen by the log (eigenvalue 0) is
    'more than 1000 %'."""
    names = ("a = x + y", "b", "c")
    v = np.array([[1, 1, 0], [0, 0, np.sqrt(2)], [1, -1, 0]]) / np.sqrt(2)     # rows: eigenvectors
    information = v.T @ np.diag([1 / 4**2, 1 / 0.5**2, 1 / 0.01**2]) @ v
    directions = prediction.poorly_excited(information, np.ones(3), names)
    assert [w for w, _ in directions] == ["0.71 (a) + 0.71 (b)", "c"]
    np.testing.assert_allclose([s for _, s in directions], [4.0, 0.5], rtol=1e-9)
    unseen = v.T @ np.diag([0.0, 1 / 0.5**2, 1 / 0.01**2]) @ v
    words = prediction.Prediction(np.zeros(3), np.zeros(3), np.zeros(3), np.ones(3), np.zeros(3),
                                  prediction.poorly_excited(unseen, np.ones(3), names), 0.3).warnings()
    assert words == ["the log leaves poorly excited: 0.71 (a) + 0.71 (b): more than 1000 % uncertain; c: 50 % "
                     "uncertain (from the log alone, of their typical size; where above 30 %, the prior holds them)"]
