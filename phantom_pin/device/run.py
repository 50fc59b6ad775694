"""What the device's two plants share about a run (phantom_pin.simulate and
mujoco_plant.simulate_mujoco): the controller's type, the result, and the checks of the arguments
and of each command the controller returns."""

from __future__ import annotations

import dataclasses
import functools
import math
from collections.abc import Callable

import numpy as np

from phantom_pin._validation import as_state
from phantom_pin.device.device import Device
from phantom_pin.exceptions import InvalidInputError

#: Most samples one call may produce (duration * rate + 1).
MAX_SAMPLES = 1_000_000
#: Most integration steps one call may take (sample periods x substeps): about 4 minutes at
#: simulate's measured 30 microseconds per RK4 step with friction and stops (DEVELOPERS.md).
MAX_STEPS = 8_000_000

#: ``controller(t, theta, dtheta) -> tau``: s, rad (3,), rad/s (3,) -> three joint torques (N m).
Controller = Callable[[float, np.ndarray, np.ndarray], object]


@dataclasses.dataclass(frozen=True)
class SimulationResult:
    """The samples of one simulate() run, K = floor(duration * rate) + 1 of them.

    ``t`` (K,) s, t[0] = 0, t[k] = k / rate. ``theta`` (K, 3) rad and ``dtheta`` (K, 3)
    rad/s: the plant's true state (not quantized). ``tau_commanded`` (K, 3) N m: what the
    controller returned at t[k]; ``tau`` (K, 3) N m: the motor torque applied over
    [t[k], t[k+1]) after saturation (the last row is never applied); ``current`` (K, 3) A:
    the winding currents of ``tau`` (None for a model without public motor data). ``tip``
    (K, 3) m: the tip position in the report's
    frame s. ``rate`` Hz and ``substeps`` (RK4 steps per sample period while a stop is
    engaged, or in every period if given to simulate) describe the run.
    """

    t: np.ndarray
    theta: np.ndarray
    dtheta: np.ndarray
    tau: np.ndarray
    tau_commanded: np.ndarray
    current: np.ndarray | None
    tip: np.ndarray
    rate: float
    substeps: int


@functools.lru_cache(maxsize=1)
def default_device() -> Device:
    """The shipped Device, built once."""
    return Device()


def positive(value: object, name: str) -> float:
    """``value`` as a finite float > 0, else InvalidInputError naming ``name`` (an integer
    beyond the floats included)."""
    try:
        number = None if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) \
            else float(value)
    except OverflowError:
        number = None
    if number is None or not math.isfinite(number) or number <= 0:
        shown = repr(value) if len(repr(value)) <= 40 else repr(value)[:37] + "..."
        raise InvalidInputError(f"expected a finite number > 0, got {shown}", argument=name)
    return number


def arguments(theta0: object, dtheta0: object, duration: object, rate: object, controller: object,
              device: object) -> tuple[np.ndarray, np.ndarray, float, float, Device, int]:
    """The arguments a plant's run shares, checked (InvalidInputError naming the bad one; theta0
    more than a turn beyond the stops is no posture of the arm; 2 to MAX_SAMPLES samples):
    (theta0, dtheta0 or zeros, duration, rate, the Device or the shipped one, the number of
    samples floor(duration * rate) + 1)."""
    theta = as_state(theta0, "theta0").copy()
    velocity = np.zeros(3) if dtheta0 is None else as_state(dtheta0, "dtheta0").copy()
    duration, rate = positive(duration, "duration"), positive(rate, "rate")
    if controller is not None and not callable(controller):
        raise InvalidInputError(f"expected a callable (t, theta, dtheta) -> tau, got {controller!r}",
                                argument="controller")
    if device is None:
        device = default_device()
    elif not isinstance(device, Device):
        raise InvalidInputError(f"expected a phantom_pin.Device or None, got {device!r}", argument="device")
    beyond = float(np.abs(device.config.limits.stops.penetration(theta)).max())
    if beyond > 2 * math.pi:
        raise InvalidInputError(f"{theta.tolist()} rad lies {beyond:.3g} rad beyond the stops, more than a turn: "
                                "no posture of the arm", argument="theta0")
    periods = duration * rate * (1 + 1e-12)
    if periods > MAX_SAMPLES:  # before the count: 1e308 s makes it inf, which no integer holds
        raise InvalidInputError(f"{duration:g} s at {rate:g} Hz gives more than {MAX_SAMPLES} samples",
                                argument="duration")
    samples = math.floor(periods) + 1
    if samples < 2:
        raise InvalidInputError(f"{duration} s is shorter than one sample period (1 / rate = {1 / rate} s)",
                                argument="duration")
    if samples > MAX_SAMPLES:
        raise InvalidInputError(f"{duration} s at {rate} Hz gives {samples} samples, more than {MAX_SAMPLES}",
                                argument="duration")
    return theta, velocity, duration, rate, device, samples


def command(tau: object, t: float) -> np.ndarray:
    """The controller's torque as a fresh (3,) float array; InvalidInputError otherwise: numbers
    only (NumPy would read strings and dates as numbers, and drop a complex value's imaginary
    part with a warning), finite."""
    try:
        raw = np.asarray(tau)
        values = raw.astype(float) if raw.dtype.kind in "iuf" and raw.shape == (3,) else None
    except (TypeError, ValueError):
        values = None
    if values is None or not all(math.isfinite(x) for x in values.tolist()):
        raise InvalidInputError(f"returned {tau!r} at t = {t:.6g} s; expected three finite joint torques (N m), "
                                "shape (3,)", argument="controller")
    return values
