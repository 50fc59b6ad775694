"""simulate(): a controller sampled at a fixed rate (1 kHz haptic loop) with a zero-order
hold, driving the plant rigid body + rotors + friction + hard stops + torque saturation."""

from __future__ import annotations

import array
import dataclasses
import functools
import itertools
import math
from typing import Callable

import numpy as np
import pinocchio as pin

from phantom_pin.config.schema import SATURATIONS
from phantom_pin.device.device import Device
from phantom_pin.dynamics.model import solve_spd
from phantom_pin.exceptions import InvalidInputError
from phantom_pin.integration import rk4_step
from phantom_pin.validation import as_state

#: Most samples one call may produce (duration * rate + 1).
MAX_SAMPLES = 1_000_000
#: Most RK4 steps one call may take (sample periods x substeps): about 4 minutes at the
#: measured 30 microseconds per step with friction and stops (DEVELOPERS.md).
MAX_STEPS = 8_000_000
#: RK4 substep h (while a stop is engaged) is chosen so that h * OMEGA <= OSCILLATION_SCALE and
#: h * RATE <= DAMPING_SCALE, OMEGA and RATE the fastest natural frequency (rad/s) and damping
#: rate (1/s) of the plant's linearised stops (see _substeps). Measured (DEVELOPERS.md): a 0.5 s
#: fall through the shipped stop within 1e-7 rad of 48 substeps at 1 substep; stiff undamped
#: stops (1e3, 1e4 N m/rad) within 5e-7 rad of 8 times the substeps.
OSCILLATION_SCALE, DAMPING_SCALE = 0.3, 0.7
#: Longest RK4 step (s) whatever the stiff terms: the free rigid body integrated at 1 ms is
#: within 3e-11 rad of a 0.1 ms integration over 0.15 s (tests/test_simulation.py).
MAX_STEP = 1e-3
#: An event (a stop engages or releases; a joint reverses, stops or breaks away) is located by
#: regula falsi (Illinois) on its function, at most EVENT_ITERATIONS RK4 steps, to
#: EVENT_TOLERANCE (s).
EVENT_ITERATIONS, EVENT_TOLERANCE = 8, 1e-9
#: Most events located within one sample period (a bound on chattering: each costs a few RK4
#: steps); beyond it a step is taken whole.
MAX_EVENTS = 12

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


def _positive(value: object, name: str) -> float:
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
    duration, rate = _positive(duration, "duration"), _positive(rate, "rate")
    if controller is not None and not callable(controller):
        raise InvalidInputError(f"expected a callable (t, theta, dtheta) -> tau, got {controller!r}",
                                argument="controller")
    if device is None:
        device = default_device()
    elif not isinstance(device, Device):
        raise InvalidInputError(f"expected a phantom_pin.Device or None, got {device!r}", argument="device")
    beyond = float(np.abs(device.config.limits.stops.penetration(theta)).max())
    if beyond > 2 * math.pi:
        raise InvalidInputError(f"{theta.tolist()} rad lies {beyond:.3g} rad beyond the stops, more than a "
                                "turn: no posture of the arm", argument="theta0")
    samples = math.floor(duration * rate * (1 + 1e-12)) + 1
    if samples < 2:
        raise InvalidInputError(f"{duration} s is shorter than one sample period (1 / rate = {1 / rate} s)",
                                argument="duration")
    if samples > MAX_SAMPLES:
        raise InvalidInputError(f"{duration} s at {rate} Hz gives {samples} samples, "
                                f"more than {MAX_SAMPLES}", argument="duration")
    return theta, velocity, duration, rate, device, samples


def _substeps(device: Device, theta0: np.ndarray, period: float, friction: bool, hard_stops: bool) -> int:
    """RK4 substeps per sample period the stiff terms ask while a stop is engaged (simulate takes
    at least its steps of MAX_STEP): period * OMEGA / OSCILLATION_SCALE and period * RATE /
    DAMPING_SCALE rounded up, at least 1.

    OMEGA and RATE bound the stiff terms' linearised rates on the smallest joint inertia m (half
    the smallest eigenvalue of M(theta0), as M varies by about 15 % across the stops): the
    stops' natural frequency OMEGA = sqrt(3 K / m) (a joint may touch its own stop and the
    coupled one, stiffness matrix eigenvalue up to 3 K) and the damping rate RATE = (3 B +
    viscous) / m. The Coulomb friction adds no stiffness: its stick phase is a mode of
    the integration, not a steep force.
    """
    stops, law = device.config.limits.stops, device.config.actuation.friction
    inertia = 0.5 * float(np.linalg.eigvalsh(device.phantom.mass_matrix(theta0)).min())
    stiffness = 3 * stops.stiffness if hard_stops else 0.0
    damping = (3 * stops.damping if hard_stops else 0.0) + (law.viscous if friction else 0.0)
    need = max(period * math.sqrt(stiffness / inertia) / OSCILLATION_SCALE,
               period * damping / inertia / DAMPING_SCALE)
    need = min(need, 2.0 * MAX_STEPS)           # beyond the bound anyway (and no ceil of inf)
    return max(1, math.ceil(need * (1 - 1e-12)))


def simulate(theta0: object, duration: float, controller: Controller | None = None, *,
             dtheta0: object = None, rate: float = 1000.0, friction: bool = True,
             hard_stops: bool = True, saturation: bool | str = True, quantization: bool = False,
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
    ``friction`` config.Friction (viscous and Coulomb in motion; a joint at rest sticks while
    the torque that holds it is below the Coulomb torque: an exact mode of the integration, no
    creep), ``hard_stops`` Device.stop_torque, and ``saturation``: tau_motor = the command
    clipped to +-Device.saturation_torque (True: actuation.yaml's policy, "continuous" by
    default; "continuous" or "peak" to choose; False: no clipping), as the MJCF's ctrlrange.
    Between samples: fixed-step RK4, one step per period (at most MAX_STEP) away from the stops
    and, by default, more while a stop is engaged, from the stiffest term at theta0 (see
    _substeps: at 1 kHz 1 or 2 for the Premium 1.5, 11 to 18 for the lighter Touch); an
    explicit ``substeps`` is the number of steps in every period, and must keep them within
    MAX_STEP. A step in which a stop engages or releases, or a friction mode ends, is cut at
    the event (regula falsi, MAX_EVENTS per step). A run is refused beyond MAX_SAMPLES samples
    or MAX_STEPS RK4 steps, counted as if every period were spent on a stop.

    ``device``: the Device to simulate (default: the shipped one, built once). ``progress``:
    called with the share of the samples done (0..1), for a progress bar.
    Raises InvalidInputError naming the bad argument, or the controller's bad return;
    MissingDataError for ``quantization`` on a model without public encoder data.
    """
    for name, flag in (("friction", friction), ("hard_stops", hard_stops), ("quantization", quantization)):
        if not isinstance(flag, (bool, np.bool_)):
            raise InvalidInputError(f"expected True or False, got {flag!r}", argument=name)
    if isinstance(saturation, (bool, np.bool_)):
        saturation = bool(saturation)       # np.True_ is not True
    elif saturation not in SATURATIONS:
        raise InvalidInputError(f"expected True, False, 'continuous' or 'peak', got {saturation!r}",
                                argument="saturation")
    theta, velocity, duration, rate, device, samples = arguments(theta0, dtheta0, duration, rate, controller,
                                                                 device)
    if quantization:
        device._require("encoder", "quantization")
    period = 1.0 / rate
    if progress is not None and not callable(progress):
        raise InvalidInputError(f"expected a callable (share done, 0..1) or None, got {progress!r}",
                                argument="progress")
    if period / MAX_STEP > MAX_STEPS:
        raise InvalidInputError(f"{rate:g} Hz needs {period / MAX_STEP:.3g} RK4 steps (at most {MAX_STEP:g} s "
                                f"each) per sample period of {period:.3g} s, more than {MAX_STEPS:.0e}",
                                argument="rate")
    fixed = substeps is not None
    free_substeps = max(1, math.ceil(period / MAX_STEP * (1 - 1e-12)))   # RK4 steps away from the stops
    if substeps is None:
        substeps = max(free_substeps, _substeps(device, theta, period, friction, hard_stops))
    elif isinstance(substeps, bool) or not isinstance(substeps, (int, np.integer)) or substeps < 1:
        raise InvalidInputError(f"expected an integer >= 1, got {substeps!r}", argument="substeps")
    elif substeps < free_substeps:
        raise InvalidInputError(f"{substeps} gives RK4 steps of {period / substeps:.3g} s at {rate:g} Hz, "
                                f"longer than {MAX_STEP:g} s (the free arm's accuracy); at least {free_substeps}",
                                argument="substeps")
    substeps = int(substeps)
    steps = (samples - 1) * substeps
    if steps > MAX_STEPS:
        argument = "substeps" if fixed else "rate" if substeps > MAX_STEPS else "duration"
        raise InvalidInputError(
            f"{duration:g} s at {rate:g} Hz needs {steps:.3g} RK4 steps ({samples - 1} periods x "
            f"{substeps:.3g} substeps of {period / substeps:.2g} s"
            + ("" if fixed else f", the step the stiffest term allows on a stop: its "
               f"{device.config.limits.stops.stiffness:g} N m/rad and the friction; a run counted as if on one")
            + f"), more than {MAX_STEPS:.0e} (about 4 minutes)", argument=argument)

    model = device.phantom.model
    data = model.createData()
    actuation = device.config.actuation
    peak_list = list(actuation.limit(actuation.saturation if saturation is True else saturation))  # N m, the clip
    bounds = list(zip(device._stop_lower.tolist(), device._stop_upper.tolist()))
    stop_force = device.config.limits.stops.force
    law = device.config.actuation.friction
    viscous, coulomb = law.viscous, law.coulomb

    # Stop coordinates c = theta1, theta2, theta3, theta2 - theta3 with their gradients
    # dc/dtheta (the rows of STOP_COORDINATES): Device.stop_torque, in scalars for speed.
    (lo0, hi0), (lo1, hi1), (lo2, hi2), (lo3, hi3) = bounds
    position, rate_vector = np.zeros(3), np.zeros(3)      # Pinocchio's inputs, filled in place

    def dynamics(q: list[float], v: list[float], tau: list[float], mode: tuple, contact: tuple | None,
                 holding: bool = False):
        """ddtheta (rad/s^2) in the friction ``mode`` (per joint +1 or -1: sliding that way,
        Coulomb friction against it; 0: stuck, ddtheta = 0, held by whatever torque that takes)
        and the stops' ``contact`` (contact_at: each engaged stop's bound, its spring and damper
        acting from it whichever side q is, so that a step is smooth up to the event that ends
        it); with ``holding``, (ddtheta, the friction torque holding each stuck joint, N m).
        M^-1 (tau - friction + stops - C dtheta - N): Phantom.forward_dynamics plus
        Device.friction and Device.stop_torque, without their per-call checks."""
        # unrolled on Python floats: this runs four times per RK4 step, and Python's cost per
        # operation is what remains beside Pinocchio's (benchmarks/bench_plants.py)
        q0, q1, q2 = q
        v0, v1, v2 = v
        t0, t1, t2 = tau
        if friction:
            m0, m1, m2 = mode
            t0 -= viscous * v0 + coulomb * m0
            t1 -= viscous * v1 + coulomb * m1
            t2 -= viscous * v2 + coulomb * m2
        if contact is not None:
            s0, s1, s2, s3 = contact
            if s0 is not None:
                t0 -= stop_force(q0 - s0, v0, True)
            if s1 is not None:
                t1 -= stop_force(q1 - s1, v1, True)
            if s2 is not None:
                t2 -= stop_force(q2 - s2, v2, True)
            if s3 is not None:
                force = stop_force(q1 - q2 - s3, v1 - v2, True)
                t1 -= force
                t2 += force
        position[0], position[1], position[2] = q0, q1, q2
        rate_vector[0], rate_vector[1], rate_vector[2] = v0, v1, v2
        b0, b1, b2 = pin.nonLinearEffects(model, data, position, rate_vector).tolist()
        rhs = (t0 - b0, t1 - b1, t2 - b2)
        mass = pin.crba(model, data, position, pin.Convention.WORLD).tolist()    # DEVELOPERS.md
        if not friction or all(mode):
            solution = solve_spd(mass, rhs)
            if solution is None:  # M(theta) includes the rotors: positive definite at every finite theta
                raise _Diverged
            return (solution, ()) if holding else solution
        return _constrained(mass, rhs, mode, holding)

    last: list = [None] * 6   # held()'s last (q, v, tau, mode, contact, result)

    def held(q: list[float], v: list[float], tau: list[float], mode: tuple, contact: tuple | None) -> list[float]:
        """The torques holding the stuck joints of ``mode`` at a state (dynamics' second part),
        the last one remembered: the end of a step is where the next one starts, and a joint
        held still is held at the same state sample after sample."""
        if not (last[0] == q and last[1] == v and last[2] == tau and last[3] == mode and last[4] == contact):
            last[:] = q, v, tau, mode, contact, dynamics(q, v, tau, mode, contact, True)[1]
        return last[5]

    def contact_at(q: list[float], v: list[float], margin: list[float]) -> tuple | None:
        """The stops engaged at a state, as each stop coordinate's bound (rad) where engaged and
        None where not; None if none is (or without stops). ``margin``: margins(q). A stop is
        engaged beyond its bound, and on it exactly if moving outwards (the step that located
        its contact may end on the boundary to the last bit)."""
        if not hard_stops or min(margin) > 0:
            return None
        q0, q1, q2 = q
        v0, v1, v2 = v
        out = []
        for c, rate, lo, hi, m in ((q0, v0, lo0, hi0, margin[0]), (q1, v1, lo1, hi1, margin[1]),
                                   (q2, v2, lo2, hi2, margin[2]), (q1 - q2, v1 - v2, lo3, hi3, margin[3])):
            lower = c - lo < hi - c
            out.append((lo if lower else hi) if m < 0 or (m == 0 and (rate < 0 if lower else rate > 0)) else None)
        return None if out == [None] * 4 else tuple(out)

    def mode_at(q: list[float], v: list[float], tau: list[float], contact: tuple | None) -> tuple:
        """The friction mode at a state: a moving joint slides; a joint at rest sticks if the
        torque that holds it is within the Coulomb torque, else it breaks away in the
        direction the net torque pushes it (released one at a time, the most overloaded first)."""
        if not friction:
            return (1, 1, 1)
        v0, v1, v2 = v
        if v0 and v1 and v2:
            return (1 if v0 > 0 else -1, 1 if v1 > 0 else -1, 1 if v2 > 0 else -1)
        mode = [1 if x > 0 else -1 if x < 0 else 0 for x in v]
        while 0 in mode:
            holding = held(q, v, tau, tuple(mode), contact)
            stuck = [i for i in range(3) if mode[i] == 0]
            worst = max(range(len(stuck)), key=lambda k: abs(holding[k]))
            if abs(holding[worst]) < coulomb:        # at the Coulomb torque it breaks away
                break
            mode[stuck[worst]] = -1 if holding[worst] > 0 else 1
        return tuple(mode)

    def slack(q: list[float], v: list[float], tau: list[float], mode: tuple, contact: tuple | None) -> list[float]:
        """How far the friction mode holds at a state, per joint (> 0 while it does): a sliding
        joint's rate along its direction (rad/s), a stuck joint's Coulomb torque less the torque
        that holds it (N m); empty without friction."""
        if not friction:
            return []
        holding = iter(held(q, v, tau, mode, contact) if not all(mode) else ())
        return [x * m if m else coulomb - abs(next(holding)) for x, m in zip(v, mode)]

    def margins(q: list[float]) -> list[float]:
        """Each stop coordinate's distance inside its range (rad; < 0 while the stop is engaged);
        empty without stops."""
        if not hard_stops:
            return []
        q0, q1, q2 = q
        c = q1 - q2
        return [q0 - lo0 if q0 - lo0 < hi0 - q0 else hi0 - q0, q1 - lo1 if q1 - lo1 < hi1 - q1 else hi1 - q1,
                q2 - lo2 if q2 - lo2 < hi2 - q2 else hi2 - q2, c - lo3 if c - lo3 < hi3 - c else hi3 - c]

    def advance(q: list[float], v: list[float], tau: list[float], h: float, depth: int) -> tuple:
        """One RK4 step of h in the friction mode and the stops' contact of the start
        (EVENT_ITERATIONS and the module doc). A step in which a stop engages or releases, or the
        friction mode ends (a sliding joint reverses or stops, a stuck one breaks away), is cut at
        the first such event, located by regula falsi (Illinois) on its function, just past it:
        a reversing joint is set at rest there, and the rest of the step starts in the modes of
        that state (mode_at decides whether it sticks). While a stop is engaged the step is at
        most contact_step."""
        start_margins = margins(q)
        contact = contact_at(q, v, start_margins)
        mode = mode_at(q, v, tau, contact)
        if friction and not any(mode):    # every joint stuck (v = 0, ddtheta = 0) for the held torque
            return q, v

        def acceleration(q_: list[float], v_: list[float]) -> tuple:
            return dynamics(q_, v_, tau, mode, contact)

        q_end, v_end = rk4_step(acceleration, q, v, h)
        end_margins = margins(q_end)
        if hard_stops and h > contact_step * (1 + 1e-9) and min(start_margins + end_margins) < 0:
            count = math.ceil(h / contact_step * (1 - 1e-12))    # a stop engaged: its substeps
            for _ in range(count):
                q, v = advance(q, v, tau, h / count, depth)
            return q, v
        # event functions, positive while the start's modes hold: friction slacks, stop margins
        # (a free stop's margin, an engaged one's depth)
        stop_signs = [1.0] * len(start_margins) if contact is None else [1.0 if c is None else -1.0 for c in contact]

        def functions(q_: list[float], v_: list[float], known: list[float] | None = None) -> list[float]:
            stop_part = margins(q_) if known is None else known
            return slack(q_, v_, tau, mode, contact) + [m * sign for m, sign in zip(stop_part, stop_signs)]

        end = functions(q_end, v_end, end_margins)
        if not end or min(end) > 0 or depth >= MAX_EVENTS:
            return q_end, v_end
        start = functions(q, v, start_margins)
        shares = [a / (a - b) if b <= 0 < a else (0.0 if b <= 0 and a > 0 else 1.0) for a, b in zip(start, end)]
        first = min(range(len(shares)), key=shares.__getitem__)
        share = shares[first]
        if share >= 1.0:                # nothing crossed from inside (a function at 0 at the start)
            return q_end, v_end
        if share <= 0.0:                # the mode ended at the start already
            share, q_end, v_end = 0.0, q, v
        else:
            # the Illinois variant of regula falsi on that function, bracketed in [low, high]
            # (> 0 at low, <= 0 at high); the step ends at high, just past the event
            low, high, at_low, at_high, side = 0.0, 1.0, start[first], end[first], 0
            for _ in range(EVENT_ITERATIONS):
                q_try, v_try = rk4_step(acceleration, q, v, share * h)
                value = functions(q_try, v_try)[first]
                if value > 0:
                    low, at_low = share, value
                    at_high, side = (at_high / 2 if side == 1 else at_high), 1
                else:
                    high, at_high, q_end, v_end = share, value, q_try, v_try
                    at_low, side = (at_low / 2 if side == -1 else at_low), -1
                if (high - low) * h <= EVENT_TOLERANCE:
                    break
                share = low + (high - low) * at_low / (at_low - at_high)
            share = high
        if first < len(mode) and friction and mode[first]:     # a sliding joint reversed or stopped: at rest
            v_end = list(v_end)
            v_end[first] = 0.0
        if share < 1.0:
            return advance(q_end, v_end, tau, (1.0 - share) * h, depth + 1)
        return q_end, v_end

    contact_step = period / substeps
    counts_per_radian = device._counts_per_radian
    if quantization:
        previous = np.rint((theta - velocity * period) * counts_per_radian) / counts_per_radian
    theta, velocity = theta.tolist(), velocity.tolist()          # the state, Python floats
    # the samples, flat buffers of doubles (appending costs less than a NumPy row assignment)
    out_theta, out_dtheta, commanded, applied = (array.array("d") for _ in range(4))
    zero = [0.0, 0.0, 0.0]
    for k in range(samples):
        if progress is not None:
            progress(k / samples)
        out_theta.extend(theta)
        out_dtheta.extend(velocity)
        t = k / rate  # as result.t: 9 / 1000 is 0.009, 9 * 0.001 is 0.009000000000000001
        if controller is None:
            tau = zero
            commanded.extend(zero)
        else:
            if quantization:
                measured = np.rint(np.array(theta) * counts_per_radian) / counts_per_radian
                seen, seen_rate = measured.copy(), (measured - previous) * rate   # a copy: the controller's
                previous = measured
            else:
                seen, seen_rate = np.array(theta), np.array(velocity)
            tau = _checked(controller(t, seen, seen_rate), t).tolist()
            commanded.extend(tau)
            if saturation:              # the clip, in floats (np.clip costs more than the plant's step)
                tau = [-p if x < -p else p if x > p else x for x, p in zip(tau, peak_list)]
        applied.extend(tau)
        if k == samples - 1:
            break
        # the stiff stops need their substeps only while engaged (advance); elsewhere
        # free_substeps (or an explicit ``substeps``)
        count = substeps if fixed else free_substeps
        try:
            for _ in range(count):
                theta, velocity = advance(theta, velocity, tau, period / count, 0)
            if not math.isfinite(sum(theta) + sum(velocity)):   # NaN or inf anywhere
                raise _Diverged
        except _Diverged:
            raise InvalidInputError(_divergence(t, _rows(out_dtheta)[0], _rows(applied), saturation)) from None
    if progress is not None:
        progress(1.0)
    theta_out, applied_out = _rows(out_theta), _rows(applied)
    return SimulationResult(
        t=np.arange(samples) / rate, theta=theta_out, dtheta=_rows(out_dtheta), tau=applied_out,
        tau_commanded=_rows(commanded),
        current=None if device.config.actuation.motor is None else device.motor_currents(applied_out),
        tip=device.phantom.forward_kinematics(theta_out)[:, :3, 3], rate=rate, substeps=substeps)


def _rows(buffer: array.array) -> np.ndarray:
    """A flat buffer of doubles as a (K, 3) array of its own."""
    return np.frombuffer(buffer, dtype=float).reshape(-1, 3).copy()


class _Diverged(Exception):
    """The integrated state left the finite numbers (inside simulate)."""


#: Per friction mode with a stuck joint: (the sliding joints, the stuck ones), in order.
_PARTS = {mode: (tuple(i for i in range(3) if mode[i]), tuple(i for i in range(3) if not mode[i]))
          for mode in itertools.product((-1, 0, 1), repeat=3) if not all(mode)}


def _constrained(mass: list[list[float]], rhs: tuple, mode: tuple,
                 holding: bool) -> list[float] | tuple[list[float], list[float]]:
    """ddtheta of M ddtheta = rhs + f with ddtheta_i = 0 and f_i free where mode[i] == 0 (stuck),
    f_i = 0 elsewhere: M_LL a_L = rhs_L; with ``holding``, (ddtheta, f_S = M_SL a_L - rhs_S).
    ``mass`` is the full symmetric 3x3 M (nested lists: crba's, DEVELOPERS.md)."""
    free, stuck = _PARTS[mode]
    a = [0.0, 0.0, 0.0]
    if len(free) == 2:
        i, j = free
        m11, m12, m22 = mass[i][i], mass[i][j], mass[j][j]
        r1, r2 = rhs[i], rhs[j]
        det = m11 * m22 - m12 * m12
        a[i] = (m22 * r1 - m12 * r2) / det
        a[j] = (m11 * r2 - m12 * r1) / det
    elif free:
        i = free[0]
        a[i] = rhs[i] / mass[i][i]
    if not holding:
        return a
    return a, [mass[s][0] * a[0] + mass[s][1] * a[1] + mass[s][2] * a[2] - rhs[s] for s in stuck]


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
    """The controller's torque as a fresh (3,) float array; InvalidInputError otherwise: numbers
    only (NumPy would read strings and dates as numbers, and drop a complex value's imaginary
    part with a warning), finite."""
    try:
        raw = np.asarray(tau)
        array = raw.astype(float) if raw.dtype.kind in "iuf" and raw.shape == (3,) else None
    except (TypeError, ValueError):
        array = None
    values = () if array is None else array.tolist()
    if array is None or not all(math.isfinite(x) for x in values):
        raise InvalidInputError(f"returned {tau!r} at t = {t:.6g} s; "
                                f"expected three finite joint torques (N m), shape (3,)", argument="controller")
    return array
