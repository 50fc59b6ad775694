"""simulate(): a controller sampled at a fixed rate (1 kHz haptic loop) with a zero-order
hold, driving the plant rigid body + rotors + friction + hard stops + torque saturation
(device.plant.Plant)."""

from __future__ import annotations

import array
import math
from collections.abc import Callable

import numpy as np

from phantom_pin.config.types import SATURATIONS
from phantom_pin.description.build import held
from phantom_pin.device.device import Device
from phantom_pin.device.plant import MAX_STEP, Diverged, Plant, contact_substeps
from phantom_pin.device.run import MAX_STEPS, Controller, SimulationResult, arguments, command, default_device
from phantom_pin.dynamics.phantom import Phantom
from phantom_pin.exceptions import InvalidInputError

__all__ = ["SimulationResult", "default_device", "simulate"]


def simulate(theta0: object, duration: float, controller: Controller | None = None, *,
             dtheta0: object = None, rate: float = 1000.0, friction: bool = True,
             hard_stops: bool = True, saturation: bool | str = True, quantization: bool = False,
             device: Device | None = None, substeps: int | None = None,
             progress: Callable[[float], None] | None = None, gimbal: object = None) -> SimulationResult:
    """Run ``controller`` against the device from rest (or ``dtheta0``) at ``theta0``.

    ``controller(t, theta, dtheta) -> tau`` (s, rad, rad/s -> three joint torques, N m) is
    called at t = k / rate; its torque is held constant until the next sample (zero-order
    hold). ``None`` commands zero torque. With ``quantization`` the controller sees theta
    rounded to encoder counts (Device.encoder_counts) and dtheta as the backward difference
    of those quantized angles over one period (at t = 0, against theta0 - dtheta0 / rate).

    Plant (device.plant.Plant): M(theta) ddtheta + C dtheta + N(theta) = tau_motor -
    tau_friction + tau_stops, with M including the rotors' reflected inertia (Pinocchio's crba and nonLinearEffects
    on the Phantom's mimic model, the computation of Phantom.forward_dynamics),
    ``friction`` config.Friction (each joint its own viscous and Coulomb friction in motion; a
    joint at rest sticks while the torque that holds it is below its Coulomb torque: an exact
    mode of the integration, no creep), ``hard_stops`` Device.stop_torque, and ``saturation``: tau_motor = the command
    clipped to +-Device.saturation_torque (True: actuation.yaml's policy, "continuous" by
    default; "continuous" or "peak" to choose; False: no clipping), as the MJCF's ctrlrange.
    Between samples: fixed-step RK4, one step per period (at most MAX_STEP) away from the stops
    and, by default, more while a stop is engaged, from the stiffest term at theta0 (see
    contact_substeps: at 1 kHz 1 or 2 for the Premium 1.5, 11 to 18 for the lighter Touch); an
    explicit ``substeps`` is the number of steps in every period, and must keep them within
    MAX_STEP. A step in which a stop engages or releases, or a friction mode ends, is cut at
    the event (regula falsi, MAX_EVENTS per step). A run is refused beyond MAX_SAMPLES samples
    or MAX_STEPS RK4 steps, counted as if every period were spent on a stop.

    ``device``: the Device to simulate (default: the shipped one, built once). ``progress``:
    called with the share of the samples done (0..1), for a progress bar. ``gimbal`` (rad,
    OpenHaptics' raw gimbal angles, (3,); a model with a stylus gimbal, the Touch): the gimbal
    held at these angles during the run instead of at ``config.gimbal.locked_at`` (the device
    of description.build.held; Phantom's methods with ``gimbal=`` give the same dynamics).
    Raises InvalidInputError naming the bad argument, or the controller's bad return;
    MissingDataError for ``quantization`` on a model without public encoder data.
    """
    saturation = _options(friction, hard_stops, quantization, saturation)
    theta, velocity, duration, rate, device, samples = arguments(theta0, dtheta0, duration, rate, controller,
                                                                 device)
    if gimbal is not None:
        device = Device(Phantom(held(device.phantom.description, gimbal)))
    if quantization:
        device.require("encoder", "quantization")
    if progress is not None and not callable(progress):
        raise InvalidInputError(f"expected a callable (share done, 0..1) or None, got {progress!r}",
                                argument="progress")
    count, substeps = _steps(device, theta, duration, rate, samples, substeps, friction, hard_stops)
    plant = Plant(device, friction=friction, hard_stops=hard_stops, saturation=saturation,
                  contact_step=1.0 / rate / substeps)
    sense = Encoders(device, theta, velocity, rate) if quantization else None
    out_theta, out_dtheta, commanded, applied = _loop(device, plant, controller, sense, theta, velocity, samples,
                                                       rate, count, progress, saturation)
    theta_out, applied_out = _rows(out_theta), _rows(applied)
    return SimulationResult(
        t=np.arange(samples) / rate, theta=theta_out, dtheta=_rows(out_dtheta), tau=applied_out,
        tau_commanded=_rows(commanded),
        current=None if device.config.actuation.motor is None else device.motor_currents(applied_out),
        tip=device.phantom.forward_kinematics(theta_out)[:, :3, 3], rate=rate, substeps=substeps)

def _loop(device: Device, plant: Plant, controller: Controller | None, sense: Encoders | None, theta: np.ndarray,
          velocity: np.ndarray, samples: int, rate: float, count: int,
          progress: Callable[[float], None] | None, saturation: bool | str) -> tuple[array.array, ...]:
    """simulate's samples: the sensed state to the controller, its torque held over each period
    (plant.hold); flat buffers (theta, dtheta, commanded, applied), three doubles a sample."""
    period = 1.0 / rate
    q, v = theta.tolist(), velocity.tolist()          # the state, Python floats
    # the samples, flat buffers of doubles (appending costs less than a NumPy row assignment)
    out_theta, out_dtheta, commanded, applied = (array.array("d") for _ in range(4))
    tau = [0.0, 0.0, 0.0]
    for k in range(samples):
        if progress is not None:
            progress(k / samples)
        out_theta.extend(q)
        out_dtheta.extend(v)
        t = k / rate  # as result.t: 9 / 1000 is 0.009, 9 * 0.001 is 0.009000000000000001
        if controller is None:
            commanded.extend(tau)                   # zero, nothing to clip
        else:
            seen = (np.array(q), np.array(v)) if sense is None else sense(q)
            tau = command(controller(t, *seen), t).tolist()
            commanded.extend(tau)
            tau = plant.saturate(tau)
        applied.extend(tau)
        if k == samples - 1:
            break
        try:
            q, v = plant.hold(q, v, tau, period, count)
        except Diverged:
            raise _divergence(t, _rows(out_dtheta)[0], _rows(applied), saturation, device,
                              _rows(out_theta)[0]) from None
    if progress is not None:
        progress(1.0)
    return out_theta, out_dtheta, commanded, applied



def _options(friction: object, hard_stops: object, quantization: object, saturation: object) -> bool | str:
    """simulate's switches checked (InvalidInputError naming the bad one): the saturation policy,
    True, False (np.bool_ as bool), "continuous" or "peak"."""
    for name, flag in (("friction", friction), ("hard_stops", hard_stops), ("quantization", quantization)):
        if not isinstance(flag, (bool, np.bool_)):
            raise InvalidInputError(f"expected True or False, got {flag!r}", argument=name)
    if isinstance(saturation, (bool, np.bool_)):
        return bool(saturation)       # np.True_ is not True
    if saturation not in SATURATIONS:
        raise InvalidInputError(f"expected True, False, 'continuous' or 'peak', got {saturation!r}",
                                argument="saturation")
    return str(saturation)


def _steps(device: Device, theta0: np.ndarray, duration: float, rate: float, samples: int, substeps: object,
           friction: bool, hard_stops: bool) -> tuple[int, int]:
    """(RK4 steps per sample period away from the stops, per period while a stop is engaged):
    ceil(period / MAX_STEP) away, and on a stop the larger of it and contact_substeps, or the
    given ``substeps`` in every period; InvalidInputError (naming rate, substeps or duration)
    for steps longer than MAX_STEP or a run beyond MAX_STEPS, counted as if on a stop."""
    period = 1.0 / rate
    if period / MAX_STEP > MAX_STEPS:
        raise InvalidInputError(f"{rate:g} Hz needs {period / MAX_STEP:.3g} RK4 steps (at most {MAX_STEP:g} s "
                                f"each) per sample period of {period:.3g} s, more than {MAX_STEPS:.0e}",
                                argument="rate")
    fixed = substeps is not None
    free = max(1, math.ceil(period / MAX_STEP * (1 - 1e-12)))   # RK4 steps away from the stops
    if substeps is None:
        substeps = max(free, contact_substeps(device, theta0, period, friction, hard_stops))
    elif isinstance(substeps, bool) or not isinstance(substeps, (int, np.integer)) or substeps < 1:
        raise InvalidInputError(f"expected an integer >= 1, got {substeps!r}", argument="substeps")
    elif substeps < free:
        raise InvalidInputError(f"{substeps} gives RK4 steps of {period / substeps:.3g} s at {rate:g} Hz, longer "
                                f"than {MAX_STEP:g} s (the free arm's accuracy); at least {free}",
                                argument="substeps")
    substeps = int(substeps)
    steps = (samples - 1) * substeps
    if steps > MAX_STEPS:
        raise InvalidInputError(
            f"{duration:g} s at {rate:g} Hz needs {steps:.3g} RK4 steps ({samples - 1} periods x "
            f"{substeps:.3g} substeps of {period / substeps:.2g} s"
            + ("" if fixed else f", the step the stiffest term allows on a stop: its "
               f"{device.config.limits.stops.stiffness:g} N m/rad and the friction; a run counted as if on one")
            + f"), more than {MAX_STEPS:.0e} (about 4 minutes)"
            + ("" if fixed or substeps <= MAX_STEPS else
               f": the device's stops (B {device.config.limits.stops.damping:g} N m s/rad) and viscous friction "
               f"(up to {max(device.config.actuation.friction.viscous):g} N m s/rad) are too stiff to simulate at any "
               "rate"),
            argument="substeps" if fixed else "device" if substeps > MAX_STEPS else "duration")
    return (substeps if fixed else free), substeps


class Encoders:
    """What the controller sees with quantization: theta (rad) rounded to encoder counts
    (Device.encoder_counts) and the backward difference of those quantized angles over one
    period (rad/s; at t = 0 against theta0 - dtheta0 / rate), as fresh arrays."""

    def __init__(self, device: Device, theta0: np.ndarray, dtheta0: np.ndarray, rate: float) -> None:
        self.counts_per_radian, self.rate = device.counts_per_radian, rate
        self.previous = np.rint((theta0 - dtheta0 * (1.0 / rate)) * self.counts_per_radian) / self.counts_per_radian

    def __call__(self, theta: list[float]) -> tuple[np.ndarray, np.ndarray]:
        measured = np.rint(np.array(theta) * self.counts_per_radian) / self.counts_per_radian
        seen_rate = (measured - self.previous) * self.rate
        self.previous = measured
        return measured.copy(), seen_rate          # a copy: the controller's


def _rows(buffer: array.array) -> np.ndarray:
    """A flat buffer of doubles as a (K, 3) array of its own."""
    return np.frombuffer(buffer, dtype=float).reshape(-1, 3).copy()


def _divergence(t: float, dtheta0: np.ndarray, applied: np.ndarray, saturation: bool | str, device: Device,
                theta0: np.ndarray) -> InvalidInputError:
    """The error of a state that diverged during the period from ``t``, naming the likely cause
    in the argument field: the largest initial rate (dtheta0) or applied torque (controller),
    what the plant was given; where both were modest, the device itself (its gravity torque at
    ``theta0``, N m, against its stops)."""
    rate, torque = float(np.abs(dtheta0).max()), float(np.abs(applied).max())
    when = f"the state diverged between t = {t:.6g} s and the next sample"
    if rate >= 1e3:
        return InvalidInputError(f"{rate:.3g} rad/s is far beyond any joint speed of the arm; {when}",
                                 argument="dtheta0")
    if not saturation and torque >= 1e3:
        return InvalidInputError(f"it applied up to {torque:.3g} N m with saturation off; {when}",
                                 argument="controller")
    if rate < 1.0 and torque < 1.0:  # neither the start nor the commands: the device's own numbers
        gravity = float(np.abs(device.phantom.gravity(theta0)).max())
        stops = device.config.limits.stops
        return InvalidInputError(f"with at most {torque:.3g} N m applied and {rate:.3g} rad/s at the start, the "
                                 f"device itself diverged: its gravity torque reaches {gravity:.3g} N m at theta0 "
                                 f"against stops of {stops.stiffness:g} N m/rad (are its masses and lengths "
                                 f"right?); {when}", argument="device")
    return InvalidInputError(f"controller or dtheta0: up to {torque:.3g} N m and {rate:.3g} rad/s at the start; {when}")
