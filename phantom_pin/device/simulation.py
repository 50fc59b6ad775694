"""simulate(): a controller sampled at a fixed rate (1 kHz haptic loop) with a zero-order
hold, driving the plant rigid body + rotors + friction + hard stops + torque saturation."""

from __future__ import annotations

import dataclasses
import functools
import math
from typing import Callable

import numpy as np
import pinocchio as pin

from phantom_pin.device.device import Device
from phantom_pin.dynamics.model import solve_spd
from phantom_pin.exceptions import InvalidInputError
from phantom_pin.integration import rk4_step
from phantom_pin.validation import as_state

#: Most samples one call may produce (duration * rate + 1).
MAX_SAMPLES = 1_000_000
#: Most RK4 steps one call may take (sample periods x substeps): about 4 minutes at the
#: measured 60 microseconds per step with friction and stops (README, "Speed").
MAX_STEPS = 4_000_000
#: RK4 substep h is chosen so that h * LAMBDA <= STEP_SCALE, LAMBDA the fastest rate (1/s)
#: of the plant's linearised stiff terms (see _substeps).
STEP_SCALE = 0.25
#: Longest RK4 step (s) whatever the stiff terms: the free rigid body integrated at 1 ms is
#: within 3e-11 rad of a 0.1 ms integration over 0.15 s (tests/test_simulation.py).
MAX_STEP = 1e-3
#: A step in which a stop engages or releases is halved this many times around the event,
#: so that RK4 never steps across the stop force's kink and damping jump by more than
#: h / 2**EVENT_BISECTIONS.
EVENT_BISECTIONS = 12

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
    frame s. ``rate`` Hz and ``substeps`` (RK4 steps per sample period) describe the run.
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


def _positive(value: object, name: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) \
            or not math.isfinite(value) or value <= 0:
        raise InvalidInputError(f"{name}: expected a finite number > 0, got {value!r}")
    return float(value)


def _substeps(device: Device, theta0: np.ndarray, period: float, friction: bool, hard_stops: bool) -> int:
    """RK4 substeps per sample period: ceil(period * LAMBDA / STEP_SCALE), and at least
    ceil(period / MAX_STEP).

    LAMBDA (1/s) bounds the fastest linearised rates of the stiff terms on the smallest
    joint inertia m (half the smallest eigenvalue of M(theta0), as M varies by about 15 %
    across the stops): the stops' natural frequency sqrt(3 K / m) (a joint may touch its own
    stop and the coupled one, stiffness matrix eigenvalue up to 3 K) and the damping rate
    (3 B + viscous + coulomb / smoothing_speed) / m (the tanh friction's slope at rest).
    """
    stops, law = device.config.limits.stops, device.config.actuation.friction
    inertia = 0.5 * float(np.linalg.eigvalsh(device.phantom.mass_matrix(theta0)).min())
    stiffness = 3 * stops.stiffness if hard_stops else 0.0
    damping = (3 * stops.damping if hard_stops else 0.0) + \
        (law.viscous + law.coulomb / law.smoothing_speed if friction else 0.0)
    fastest = max(math.sqrt(stiffness / inertia), damping / inertia)
    return max(1, math.ceil(period * fastest / STEP_SCALE), math.ceil(period / MAX_STEP * (1 - 1e-12)))


def simulate(theta0: object, duration: float, controller: Controller | None = None, *,
             dtheta0: object = None, rate: float = 1000.0, friction: bool = True,
             hard_stops: bool = True, saturation: bool = True, quantization: bool = False,
             device: Device | None = None, substeps: int | None = None,
             progress: Callable[[float], None] | None = None) -> SimulationResult:
    """Run ``controller`` against the device from rest (or ``dtheta0``) at ``theta0``.

    ``controller(t, theta, dtheta) -> tau`` (s, rad, rad/s -> three joint torques, N m) is
    called at t = k / rate; its torque is held constant until the next sample (zero-order
    hold). ``None`` commands zero torque. With ``quantization`` the controller sees theta
    rounded to encoder counts (Device.encoder_counts) and dtheta as the backward difference
    of those quantized angles over one period (at t = 0, against theta0 - dtheta0 / rate).

    Plant: M(theta) ddtheta + C dtheta + N(theta) = tau_motor - tau_friction + tau_stops,
    with M including the rotors' reflected inertia (Pinocchio's crba and nonLinearEffects
    on the Phantom's mimic model, the computation of Phantom.forward_dynamics),
    ``friction`` Device.friction, ``hard_stops`` Device.stop_torque, and with
    ``saturation`` tau_motor = the command clipped to +-Device.peak_torque (the motors'
    stall torque, or the configuration's joint_torque_limit). Between samples: fixed-step RK4
    with ``substeps`` steps per period
    (default from the stiffest term, see _substeps: 4 at 1 kHz with the shipped numbers),
    and a step in which a stop engages or releases is bisected around the event
    (EVENT_BISECTIONS halvings).

    ``device``: the Device to simulate (default: the shipped one, built once). ``progress``:
    called with the share of the samples done (0..1), for a progress bar.
    Raises InvalidInputError naming the bad argument, or the controller's bad return;
    MissingDataError for ``quantization`` on a model without public encoder data.
    """
    for name, flag in (("friction", friction), ("hard_stops", hard_stops), ("saturation", saturation),
                       ("quantization", quantization)):
        if not isinstance(flag, (bool, np.bool_)):
            raise InvalidInputError(f"{name}: expected True or False, got {flag!r}")
    theta = as_state(theta0, "theta0").copy()
    velocity = np.zeros(3) if dtheta0 is None else as_state(dtheta0, "dtheta0").copy()
    duration, rate = _positive(duration, "duration"), _positive(rate, "rate")
    if controller is not None and not callable(controller):
        raise InvalidInputError(f"controller: expected a callable (t, theta, dtheta) -> tau, got {controller!r}")
    if device is None:
        device = default_device()
    elif not isinstance(device, Device):
        raise InvalidInputError(f"device: expected a phantom_pin.Device or None, got {device!r}")
    if quantization:
        device._require("encoder", "quantization")
    beyond = float(np.abs(device.config.limits.stops.penetration(theta)).max())
    if beyond > 2 * math.pi:
        raise InvalidInputError(f"theta0: {theta.tolist()} rad lies {beyond:.3g} rad beyond the stops, more than a "
                                "turn: no posture of the arm")
    samples = math.floor(duration * rate * (1 + 1e-12)) + 1
    if samples < 2:
        raise InvalidInputError(f"duration: {duration} s is shorter than one sample period (1 / rate = {1 / rate} s)")
    if samples > MAX_SAMPLES:
        raise InvalidInputError(f"duration: {duration} s at {rate} Hz gives {samples} samples, "
                                f"more than {MAX_SAMPLES}")
    period = 1.0 / rate
    if substeps is None:
        substeps = _substeps(device, theta, period, friction, hard_stops)
    elif isinstance(substeps, bool) or not isinstance(substeps, (int, np.integer)) or substeps < 1:
        raise InvalidInputError(f"substeps: expected an integer >= 1, got {substeps!r}")
    substeps = int(substeps)
    steps = (samples - 1) * substeps
    if steps > MAX_STEPS:
        argument = "rate" if substeps > MAX_STEPS else "duration"
        raise InvalidInputError(
            f"{argument}: {duration:g} s at {rate:g} Hz needs {steps:.3g} RK4 steps ({samples - 1} periods x "
            f"{substeps:.3g} substeps of {period / substeps:.2g} s, the step the stiffest term allows: the stops' "
            f"{device.config.limits.stops.stiffness:g} N m/rad and the friction), more than {MAX_STEPS:.0e} "
            f"(about 4 minutes)")

    model = device.phantom.model
    data = model.createData()
    peak = device.peak_torque
    bounds = list(zip(device._stop_lower.tolist(), device._stop_upper.tolist()))
    stop_force = device.config.limits.stops.force
    friction_torque = device.config.actuation.friction.torque

    # Stop coordinates c = theta1, theta2, theta3, theta2 - theta3 with their gradients
    # dc/dtheta (the rows of STOP_COORDINATES): Device.stop_torque, in scalars for speed.
    stops = [(0, None, *bounds[0]), (1, None, *bounds[1]), (2, None, *bounds[2]), (1, 2, *bounds[3])]

    def acceleration(q: np.ndarray, v: np.ndarray, tau: list[float]) -> np.ndarray:
        """M^-1 (tau - friction + stops - C dtheta - N): Phantom.forward_dynamics plus
        Device.friction and Device.stop_torque, without their per-call checks."""
        qs, vs, total = q.tolist(), v.tolist(), list(tau)
        if friction:
            total = [total[0] - friction_torque(vs[0]), total[1] - friction_torque(vs[1]),
                     total[2] - friction_torque(vs[2])]
        if hard_stops:
            for i, j, lo, hi in stops:
                c, rate = (qs[i], vs[i]) if j is None else (qs[i] - qs[j], vs[i] - vs[j])
                depth = c - hi if c > hi else c - lo if c < lo else 0.0
                if depth:
                    force = stop_force(depth, rate)
                    total[i] -= force
                    if j is not None:
                        total[j] += force
        bias = pin.nonLinearEffects(model, data, q, v).tolist()
        solution = solve_spd(pin.crba(model, data, q).tolist(),
                             (total[0] - bias[0], total[1] - bias[1], total[2] - bias[2]))
        if solution is None:  # M(theta) includes the rotors: positive definite at every finite theta
            raise _Diverged
        return np.array(solution)

    def contacts(q: np.ndarray) -> list[bool]:
        """Which stops are engaged at q."""
        qs = q.tolist()
        return [not lo <= (qs[i] if j is None else qs[i] - qs[j]) <= hi for i, j, lo, hi in stops]

    def advance(q: np.ndarray, v: np.ndarray, tau: np.ndarray, h: float, depth: int) -> tuple:
        """One RK4 step of h; a step across a stop's boundary is bisected (event location)."""
        q_end, v_end = rk4_step(lambda q_, v_: acceleration(q_, v_, tau), q, v, h)
        if hard_stops and depth < EVENT_BISECTIONS and contacts(q) != contacts(q_end):
            q_mid, v_mid = advance(q, v, tau, 0.5 * h, depth + 1)
            return advance(q_mid, v_mid, tau, 0.5 * h, depth + 1)
        return q_end, v_end

    h = period / substeps
    counts_per_radian = device._counts_per_radian
    if quantization:
        previous = np.rint((theta - velocity * period) * counts_per_radian) / counts_per_radian
    out_theta, out_dtheta = np.empty((samples, 3)), np.empty((samples, 3))
    commanded, applied = np.zeros((samples, 3)), np.zeros((samples, 3))
    zero = np.zeros(3)
    for k in range(samples):
        if progress is not None:
            progress(k / samples)
        out_theta[k], out_dtheta[k] = theta, velocity
        t = k / rate  # as result.t: 9 / 1000 is 0.009, 9 * 0.001 is 0.009000000000000001
        if controller is None:
            tau = zero
        else:
            if quantization:
                measured = np.rint(theta * counts_per_radian) / counts_per_radian
                seen, seen_rate = measured, (measured - previous) * rate
                previous = measured
            else:
                seen, seen_rate = theta.copy(), velocity.copy()
            tau = _checked(controller(t, seen, seen_rate), t)
            commanded[k] = tau
            if saturation:
                tau = np.clip(tau, -peak, peak)
            applied[k] = tau
        tau = tau.tolist()
        if k == samples - 1:
            break
        try:
            for _ in range(substeps):
                theta, velocity = advance(theta, velocity, tau, h, 0)
            if not (np.isfinite(theta).all() and np.isfinite(velocity).all()):
                raise _Diverged
        except _Diverged:
            raise InvalidInputError(_divergence(t, out_dtheta[0], applied[:k + 1], saturation)) from None
    return SimulationResult(
        t=np.arange(samples) / rate, theta=out_theta, dtheta=out_dtheta, tau=applied,
        tau_commanded=commanded,
        current=None if device.config.actuation.motor is None else device.motor_currents(applied),
        tip=device.phantom.forward_kinematics(out_theta)[:, :3, 3], rate=rate, substeps=substeps)


class _Diverged(Exception):
    """The integrated state left the finite numbers (inside simulate)."""


def _divergence(t: float, dtheta0: np.ndarray, applied: np.ndarray, saturation: bool) -> str:
    """One line naming the likely cause of a state that diverged during the period from ``t``:
    the largest initial rate or applied torque (what the plant was given)."""
    rate, torque = float(np.abs(dtheta0).max()), float(np.abs(applied).max())
    if rate >= 1e3:
        cause = f"dtheta0: {rate:.3g} rad/s is far beyond any joint speed of the arm"
    elif not saturation and torque >= 1e3:
        cause = f"controller: it applied up to {torque:.3g} N m with saturation off"
    else:
        cause = f"controller or dtheta0: up to {torque:.3g} N m and {rate:.3g} rad/s at the start"
    return f"{cause}; the state diverged between t = {t:.6g} s and the next sample"


def _checked(tau: object, t: float) -> np.ndarray:
    """The controller's torque as a fresh (3,) float array; InvalidInputError otherwise (complex
    values included: NumPy would drop their imaginary part with a warning)."""
    try:
        array = None if np.iscomplexobj(tau) else np.array(tau, dtype=float)
    except (TypeError, ValueError):
        array = None
    if array is None or array.shape != (3,) or not np.isfinite(array).all():
        raise InvalidInputError(f"controller: returned {tau!r} at t = {t:.6g} s; "
                                f"expected three finite joint torques (N m), shape (3,)")
    return array
