"""A simulated device logging an identification run: the device's own plant (phantom_pin.simulate:
the rigid body with its rotors, friction, stops and saturation, RK4 with a zero-order hold)
tracking a trajectory with feed-forward plus PD, as ``phantom-pin simulate --trajectory`` does.

``phantom_pin.device.controllers.tracking`` is that controller; ``track(device, ...)`` runs it and
returns the Log a real device would write: the encoder's angles (quantized, with an encoder)
and the *commanded* torques, each held until the next sample ("held" timing), while the plant
receives them plus white noise (an amplifier's error the log does not see).
"""

from __future__ import annotations

import numpy as np

from phantom_pin.device.controllers import tracking
from phantom_pin.device.device import Device
from phantom_pin.device.simulation import simulate
from phantom_pin.exceptions import InvalidInputError
from phantom_pin.identification.io import Log


def track(device: Device, t: np.ndarray, theta: np.ndarray, dtheta: np.ndarray, tau: np.ndarray,
          torque_noise: float = 0.0, quantization: bool = True, seed: int = 0) -> Log:
    """The log of ``device`` tracking the trajectory (``tracking``'s arguments; its rate is the
    log's) from its first state: times, the encoder's angles (with ``quantization``, which needs
    the device's encoder; else the true ones) and the commanded torques (N m), the plant
    receiving them plus white noise of standard deviation ``torque_noise`` (N m, seeded)."""
    if not isinstance(device, Device):
        raise InvalidInputError(f"device: expected a phantom_pin.Device, got {device!r}")
    if isinstance(torque_noise, bool) or not isinstance(torque_noise, (int, float)) or \
            not (np.isfinite(torque_noise) and torque_noise >= 0):
        raise InvalidInputError(f"torque_noise: expected a finite number >= 0 (N m), got {torque_noise!r}")
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise InvalidInputError(f"seed: expected an integer >= 0, got {seed!r}")
    try:
        t, theta, dtheta, tau = (np.asarray(x, float) for x in (t, theta, dtheta, tau))
    except (TypeError, ValueError):
        raise InvalidInputError("t, theta, dtheta, tau: expected arrays of numbers") from None
    if t.ndim != 1 or len(t) < 2 or any(x.shape != (len(t), 3) for x in (theta, dtheta, tau)):
        raise InvalidInputError(f"t, theta, dtheta, tau: expected shapes (N,), (N, 3), (N, 3), (N, 3) with N >= 2, "
                                f"got {t.shape}, {theta.shape}, {dtheta.shape}, {tau.shape}")
    if not all(np.isfinite(x).all() for x in (t, theta, dtheta, tau)):
        raise InvalidInputError("t, theta, dtheta, tau: must be finite (no NaN or inf)")
    step = np.diff(t)
    if not (step > 0).all() or np.ptp(step) > 1e-6 * step.mean():
        raise InvalidInputError("t: the times must increase at a fixed rate")
    follow = tracking(t, theta, dtheta, tau)
    rng = np.random.default_rng(seed)
    commanded = np.zeros((len(t), 3))

    def controller(time: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        k = min(int(round(time * rate)), len(t) - 1)
        commanded[k] = follow(time, q, v)
        return commanded[k] + torque_noise * rng.standard_normal(3)

    rate = (len(t) - 1) / (t[-1] - t[0])
    result = simulate(theta[0], t[-1] - t[0], controller, dtheta0=dtheta[0], rate=rate, device=device,
                      quantization=quantization)
    measured = device.encoder_theta(device.encoder_counts(result.theta)) if quantization else result.theta
    return Log(result.t, measured, commanded[:len(result.t)])
