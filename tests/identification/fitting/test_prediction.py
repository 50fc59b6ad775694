"""identification.prediction against laws: the torques' standard deviation against a seeded
Monte Carlo of the parameters, and the poorly excited directions of a known information matrix."""

import numpy as np
import pytest

from phantom_pin.identification.fitting import prediction


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


def test_a_poorly_excited_direction_spread_over_many_parameters_is_named_by_its_largest_three():
    """A poorly excited direction is named by its three largest components, also when none has
    more than 0.2 of its square (spread over many parameters). Unit vector by hand: the three
    largest."""
    from phantom_pin.identification.fitting import prediction

    vector = np.array([3.0, -3.0, 2.9, 2.0, 2.0, 2.0, 2.0, 2.0, 2.0, 2.0, 2.0])
    vector /= np.linalg.norm(vector)                 # largest square 9 / 58.41 = 0.154
    names = tuple(f"p{k}" for k in range(len(vector)))
    a, c = 3 / np.sqrt(58.41), 2.9 / np.sqrt(58.41)
    assert prediction._words(vector, names) == f"{a:.2f} (p0) - {a:.2f} (p1) + {c:.2f} (p2)"


@pytest.mark.parametrize("ratio, refused", [(1.12, True), (1.08, False)])
def test_a_model_worse_than_the_prior_by_more_than_10_percent_is_refused(ratio, refused):
    """A fit worse than the prior by more than 10 % on a joint's log is refused, 8 % is not (the
    module's 1.1, "markedly worse")."""
    from phantom_pin.identification.fitting import prediction

    shares = dict(log=np.zeros(3), states=np.zeros(3), prior_states=np.zeros(3), directions=(), spread=0.3)
    prior_log = np.array([0.01, 0.02, 0.03])
    fit_log = prior_log * [1.0, ratio, 1.0]
    assert (prediction.Prediction(fit_log=fit_log, prior_log=prior_log, **shares).worse() is not None) == refused
