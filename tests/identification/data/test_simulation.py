"""simulation.track's errors the log does not see: per-joint ``gains`` between the command and
the plant, per-joint ``torque_noise`` and a ``disturbance`` of the true state, each against
simulate itself (its own encoder model and zero-order hold) or against an equivalent run."""

import numpy as np
import pytest

from phantom_pin import Device, Phantom, describe, simulate
from phantom_pin.device.controllers import tracking
from phantom_pin.exceptions import InvalidInputError, PhantomPinError
from phantom_pin.identification.data import simulation

DEVICE = Device(Phantom(describe()))
RATE = 1000.0


def motion(duration=1.0):
    """A smooth motion around (0, 0.3, 0.45) rad inside every stop and the shipped model's
    torques for it: (t s, theta rad, dtheta rad/s, tau N m)."""
    t = np.arange(int(round(duration * RATE)) + 1) / RATE
    w, a = 2 * np.pi * np.array([0.7, 0.9, 1.1]), np.array([0.3, 0.2, 0.25])
    theta = np.array([0.0, 0.3, 0.45]) + a * np.sin(w * t[:, None])
    dtheta, ddtheta = a * w * np.cos(w * t[:, None]), -a * w**2 * np.sin(w * t[:, None])
    assert (DEVICE.config.limits.slack(theta) > 0.05).all()
    return t, theta, dtheta, Phantom(DEVICE.phantom.description).inverse_dynamics(theta, dtheta, ddtheta)


def test_gains_scale_what_the_plant_receives_and_the_log_holds_the_command():
    """track with joint 2's gain 1.02 against simulate run with the tracking controller scaled
    by 1.02 on joint 2 (simulate's own encoder quantization): the same encoder angles, exactly,
    and the log's torques are simulate's commands divided by the gains (within rounding)."""
    t, theta, dtheta, tau = motion()
    gains = np.array([1.0, 1.02, 1.0])
    log = simulation.track(DEVICE, t, theta, dtheta, tau, gains=gains)
    follow = tracking(t, theta, dtheta, tau)
    reference = simulate(theta[0], t[-1], lambda time, q, v: gains * follow(time, q, v), dtheta0=dtheta[0],
                         rate=RATE, device=DEVICE, quantization=True)
    np.testing.assert_array_equal(log.theta, DEVICE.encoder_theta(DEVICE.encoder_counts(reference.theta)))
    np.testing.assert_allclose(log.tau, reference.tau_commanded / gains, rtol=0, atol=1e-15)
    plain = simulation.track(DEVICE, t, theta, dtheta, tau)
    assert np.abs(plain.theta - log.theta).max() > 1e-4        # the gain moved the arm (rad)


def test_a_constant_disturbance_is_a_shifted_feed_forward():
    """A constant disturbance d (N m) moves the plant as the feed-forward tau + d does: the same
    angles (within 1e-9 rad: only the order of the additions differs), the log's torques d
    apart (the log holds the command, not the disturbance)."""
    t, theta, dtheta, tau = motion()
    d = np.array([0.01, -0.02, 0.015])
    disturbed = simulation.track(DEVICE, t, theta, dtheta, tau, quantization=False, disturbance=lambda *_: d)
    shifted = simulation.track(DEVICE, t, theta, dtheta, tau + d, quantization=False)
    assert np.abs(disturbed.theta - shifted.theta).max() < 1e-9
    assert np.abs(disturbed.tau + d - shifted.tau).max() < 1e-6


def test_the_disturbance_sees_the_plants_true_state():
    """With quantization the controller sees encoder counts, the disturbance the plant's state:
    the angles it receives are not on the encoder's grid, and quantized they are the log's."""
    t, theta, dtheta, tau = motion(0.3)
    seen = []

    def record(time, q, v):
        seen.append(q)
        return np.zeros(3)
    log = simulation.track(DEVICE, t, theta, dtheta, tau, disturbance=record)
    seen = np.array(seen)
    np.testing.assert_array_equal(DEVICE.encoder_theta(DEVICE.encoder_counts(seen)), log.theta)
    assert np.abs(seen - log.theta).max() > 0.1 * DEVICE.encoder_resolution.min()


def test_torque_noise_per_joint():
    """Three equal noise levels are the one number (the same seeded draws); a joint without noise
    differs from a noisy run."""
    t, theta, dtheta, tau = motion(0.3)
    one = simulation.track(DEVICE, t, theta, dtheta, tau, torque_noise=0.003, quantization=False, seed=2)
    three = simulation.track(DEVICE, t, theta, dtheta, tau, torque_noise=(0.003,) * 3, quantization=False, seed=2)
    np.testing.assert_array_equal(one.theta, three.theta)
    quiet = simulation.track(DEVICE, t, theta, dtheta, tau, torque_noise=(0.003, 0.0, 0.003), quantization=False,
                             seed=2)
    assert np.abs(quiet.theta - one.theta).max() > 0


@pytest.mark.parametrize("kwargs, argument", [
    ({"gains": 0.0}, "gains"), ({"gains": (1.0, -1.02, 1.0)}, "gains"), ({"gains": (1.0, 1.02)}, "gains"),
    ({"gains": float("nan")}, "gains"), ({"gains": "1.02"}, "gains"), ({"gains": True}, "gains"),
    ({"torque_noise": (0.0, -0.001, 0.0)}, "torque_noise"), ({"torque_noise": float("inf")}, "torque_noise"),
    ({"disturbance": 0.01}, "disturbance"), ({"disturbance": lambda *_: np.zeros(2)}, "disturbance"),
    ({"disturbance": lambda *_: np.full(3, np.nan)}, "disturbance"),
])
def test_bad_gains_noise_and_disturbances_are_refused_naming_them(kwargs, argument):
    t, theta, dtheta, tau = motion(0.01)
    with pytest.raises(InvalidInputError) as caught:
        simulation.track(DEVICE, t, theta, dtheta, tau, **kwargs)
    assert isinstance(caught.value, (ValueError, PhantomPinError)) and caught.value.argument == argument
