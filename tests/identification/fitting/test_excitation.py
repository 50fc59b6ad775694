"""identification.fitting.excitation: the Fourier series against its own derivatives by finite
differences and its start at rest, the torque bound against the URDF's efforts, and optimise's
refusals (moved from test_estimation.py: each bad argument named)."""

import numpy as np
import pytest

from phantom_pin import Phantom, PhantomPinError, describe
from phantom_pin.identification.fitting import excitation

PHANTOM = Phantom()


def excitation_optimise(**kwargs):
    return excitation.optimise(PHANTOM, **kwargs)


@pytest.mark.parametrize("call, argument", [
    (lambda: excitation_optimise(period=-1.0), "period"), (lambda: excitation_optimise(harmonics=1), "harmonics"),
    (lambda: excitation_optimise(harmonics=2.5), "harmonics"), (lambda: excitation_optimise(margin=np.nan), "margin"),
    (lambda: excitation_optimise(torque_share=-1.0), "torque_share"),
    (lambda: excitation_optimise(restarts=0), "restarts"),
    (lambda: excitation_optimise(seed=-1), "seed"), (lambda: excitation_optimise(times=[np.nan]), "times"),
])
def test_the_excitation_checks_its_arguments(call, argument):
    """Each bad argument a new user tried (a review): one PhantomPinError and ValueError naming
    it, before any work (before: LinAlgError, TypeError, RuntimeError, a silent result)."""
    with pytest.raises(PhantomPinError, match=f"^{argument}: ") as error:
        call()
    assert isinstance(error.value, ValueError)


def _series(seed=0, harmonics=5, period=5.0):
    free = np.random.default_rng(seed).normal(size=3 + 2 * 3 * (harmonics - 1)) * 0.2
    return excitation.Fourier.from_free(free, harmonics, period)


def test_the_series_starts_at_rest_and_is_periodic():
    """from_free's last harmonic makes dtheta(0) = ddtheta(0) = 0 (1e-15 rad/s, rad/s^2); the
    series returns to its start after one period (1e-12); theta(0) = q0 - sum(b / (k w))."""
    series = _series()
    theta, dtheta, ddtheta = series(np.array([0.0, series.period]))
    np.testing.assert_allclose(dtheta, 0.0, atol=1e-14)
    np.testing.assert_allclose(ddtheta, 0.0, atol=1e-14)
    np.testing.assert_allclose(theta[1], theta[0], atol=1e-12)
    w = 2 * np.pi / series.period
    k = np.arange(1, 6)
    np.testing.assert_allclose(theta[0], series.q0 - (series.b / (k * w)).sum(axis=1), rtol=0, atol=1e-15)


def test_the_series_derivatives_are_its_finite_differences():
    """dtheta and ddtheta against central differences of theta and dtheta (h = 1e-5 s: an error
    of h^2 times the fifth harmonic's cube, below 1e-7)."""
    series = _series(1)
    t = np.linspace(0.1, 4.9, 17)
    h = 1e-5
    theta, dtheta, ddtheta = series(t)
    np.testing.assert_allclose((series(t + h)[0] - series(t - h)[0]) / (2 * h), dtheta, rtol=0, atol=1e-7)
    np.testing.assert_allclose((series(t + h)[1] - series(t - h)[1]) / (2 * h), ddtheta, rtol=0, atol=1e-6)


def test_the_torque_bound_is_the_urdfs_effort():
    """continuous_effort: each joint's <limit effort> of the URDF describe() generates."""
    import xml.etree.ElementTree as ElementTree

    description = describe()
    joints = {j.get("name"): j for j in ElementTree.fromstring(description.urdf).findall("joint")}
    effort = [float(joints[f"joint{k}"].find("limit").get("effort")) for k in (1, 2, 3)]
    np.testing.assert_allclose(excitation.continuous_effort(description), effort, rtol=1e-12)
