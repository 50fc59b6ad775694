"""A simulated device logging an identification run: the device's own plant (phantom_pin.simulate:
the rigid body with its rotors, friction, stops and saturation, RK4 with a zero-order hold)
tracking a trajectory with feed-forward plus PD, as ``phantom-pin simulate --trajectory`` does.

``phantom_pin.device.controllers.tracking`` is that controller; ``track(device, ...)`` runs it and
returns the Log a real device would write: the encoder's angles (quantized, with an encoder)
and the *commanded* torques, each held until the next sample ("held" timing), while the plant
receives them plus white noise (an amplifier's error the log does not see). What the log does
not see may be made worse: per-joint ``gains`` between the command and the torque the plant
receives (a torque constant or an amplifier off by a share), and a ``disturbance``, a torque
of the true state added to the plant's input (friction the configuration's law does not hold).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from phantom_pin._validation import fixed_rate
from phantom_pin.device.controllers import tracking
from phantom_pin.device.device import Device
from phantom_pin.device.simulation import Encoders, simulate
from phantom_pin.exceptions import InvalidInputError
from phantom_pin.identification.data.io import Log


def _per_joint(value: object, name: str, unit: str, least: float, strict: bool) -> np.ndarray:
    """``value`` as a (3,) array of finite numbers >= ``least`` (> with ``strict``): one number
    for all joints or three; InvalidInputError naming ``name`` otherwise."""
    bound = f"{'>' if strict else '>='} {least:g}"
    try:
        raw = np.asarray(value)          # numbers only: NumPy would read "1.02" as a number
        array = np.broadcast_to(raw.astype(float), (3,)).copy() if raw.dtype.kind in "iuf" else None
    except (TypeError, ValueError):
        array = None
    if array is None or not np.isfinite(array).all() or ((array <= least) if strict else (array < least)).any():
        raise InvalidInputError(f"expected a finite number {bound} ({unit}) or three, one per joint, got {value!r}",
                                argument=name)
    return array


def _trajectory(t: np.ndarray, theta: np.ndarray, dtheta: np.ndarray,
                tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """track's trajectory as float arrays, checked: shapes (N,) and (N, 3) with N >= 2, finite,
    the times at a fixed rate; InvalidInputError otherwise."""
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
        raise InvalidInputError("the times must increase at a fixed rate", argument="t")
    return t, theta, dtheta, tau


def track(device: Device, t: np.ndarray, theta: np.ndarray, dtheta: np.ndarray, tau: np.ndarray,
          torque_noise: float | np.ndarray = 0.0, quantization: bool = True, seed: int = 0,
          gains: float | np.ndarray = 1.0,
          disturbance: Callable[[float, np.ndarray, np.ndarray], np.ndarray] | None = None) -> Log:
    """The log of ``device`` tracking the trajectory (``tracking``'s arguments; its rate is the
    log's) from its first state: times, the encoder's angles (with ``quantization``, which needs
    the device's encoder; else the true ones) and the commanded torques (N m), the plant
    receiving ``gains`` x the command (per joint, dimensionless: 1.02 on joint 2 for a torque
    constant 2 % above the one the log's torques were converted with) plus white noise of
    standard deviation ``torque_noise`` (N m, one number or one per joint, seeded) plus
    ``disturbance(time, theta, dtheta)`` (N m, (3,)), evaluated at each sample on the plant's
    true state (time s from the start, rad, rad/s; not the encoder's) and held, like the
    command, until the next sample. InvalidInputError naming the argument for bad input."""
    if not isinstance(device, Device):
        raise InvalidInputError(f"expected a phantom_pin.Device, got {device!r}", argument="device")
    noise = _per_joint(torque_noise, "torque_noise", "N m", 0.0, strict=False)
    gain = _per_joint(gains, "gains", "dimensionless", 0.0, strict=True)
    if disturbance is not None and not callable(disturbance):
        raise InvalidInputError(f"expected a callable (time, theta, dtheta) -> three torques (N m), or None, got "
                                f"{disturbance!r}", argument="disturbance")
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise InvalidInputError(f"expected an integer >= 0, got {seed!r}", argument="seed")
    t, theta, dtheta, tau = _trajectory(t, theta, dtheta, tau)
    if quantization:
        device.require("encoder", "quantization")
    follow = tracking(t, theta, dtheta, tau)
    rng = np.random.default_rng(seed)
    commanded = np.zeros((len(t), 3))
    rate = fixed_rate(t)
    # what the controller sees: simulate's own encoder model (the true state stays the plant's,
    # for the disturbance)
    sense = Encoders(device, theta[0], dtheta[0], rate) if quantization else None

    def controller(time: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        k = min(int(round(time * rate)), len(t) - 1)
        commanded[k] = follow(time, *((q, v) if sense is None else sense(q.tolist())))
        applied = gain * commanded[k] + noise * rng.standard_normal(3)
        if disturbance is not None:
            extra = np.asarray(disturbance(time, q.copy(), v.copy()), dtype=float)
            if extra.shape != (3,) or not np.isfinite(extra).all():
                raise InvalidInputError(f"returned {extra!r} at t = {time:.6g} s; expected three finite torques (N m)",
                                        argument="disturbance")
            applied = applied + extra
        return applied

    result = simulate(theta[0], t[-1] - t[0], controller, dtheta0=dtheta[0], rate=rate, device=device)
    measured = device.encoder_theta(device.encoder_counts(result.theta)) if quantization else result.theta
    return Log(result.t, measured, commanded[:len(result.t)])
