"""The plant that simulate() drives between two samples: the arm's rigid body with its rotors'
reflected inertia, friction with an exact stick phase, the hard stops and torque saturation,
integrated by fixed-step RK4 with the events that end a step's friction mode or stop contact
located by regula falsi (docs/simulation.md says why each part is what it is; DEVELOPERS.md the
measurements behind its speed).

States are three Python floats of joint angles (rad) and three of rates (rad/s), as lists;
torques three floats (N m) at the joints. Floats, an unrolled RK4 (phantom_pin._integration),
a solve per friction mode and the torque that holds a stuck joint remembered from one step's
end for the next step's start are what make the plant as fast as MuJoCo's loop.
"""

from __future__ import annotations

import functools
import itertools
import math
from collections.abc import Callable, Sequence
from typing import Literal, cast, overload

import numpy as np
import pinocchio as pin

from phantom_pin._integration import rk4_step
from phantom_pin.device.device import Device
from phantom_pin.device.run import MAX_STEPS
from phantom_pin.dynamics.phantom import solve_spd

#: RK4 substep h (while a stop is engaged) is chosen so that h * OMEGA <= OSCILLATION_SCALE and
#: h * RATE <= DAMPING_SCALE, OMEGA and RATE the fastest natural frequency (rad/s) and damping
#: rate (1/s) of the plant's linearised stops (see contact_substeps). Measured (DEVELOPERS.md):
#: a 0.5 s fall through the shipped stop within 1e-7 rad of 48 substeps at 1 substep; stiff
#: undamped stops (1e3, 1e4 N m/rad) within 5e-7 rad of 8 times the substeps.
OSCILLATION_SCALE, DAMPING_SCALE = 0.3, 0.7
#: Longest RK4 step (s) whatever the stiff terms: the free rigid body integrated at 1 ms is
#: within 3e-11 rad of a 0.1 ms integration over 0.15 s (tests/device/test_simulation.py).
MAX_STEP = 1e-3
#: An event (a stop engages or releases; a joint reverses, stops or breaks away) is located by
#: regula falsi (Illinois) on its function, at most EVENT_ITERATIONS RK4 steps, to
#: EVENT_TOLERANCE (s).
EVENT_ITERATIONS, EVENT_TOLERANCE = 8, 1e-9
#: Most events located within one step (a bound on chattering: each costs a few RK4 steps);
#: beyond it a step is taken whole.
MAX_EVENTS = 12

#: A friction mode: per joint +1 or -1 (sliding that way, Coulomb friction against it) or 0 (stuck).
Mode = tuple[int, int, int]
#: The stops' contact: per stop coordinate (theta1, theta2, theta3, theta2 - theta3) the bound
#: (rad) its spring and damper act from while engaged, None where free; None when none is.
Contact = tuple[float | None, ...] | None
#: The stop law K depth + B rate (config.Stops.force) on one coordinate: (rad, rad/s, engaged) -> N m.
StopForce = Callable[[float, float, bool], float]
List3 = list[float]


class Diverged(Exception):
    """The integrated state left the finite numbers (M(theta) singular, or NaN or inf)."""


def contact_substeps(device: Device, theta0: np.ndarray, period: float, friction: bool, hard_stops: bool) -> int:
    """RK4 substeps per sample period the stiff terms ask while a stop is engaged (simulate takes
    at least its steps of MAX_STEP): period * OMEGA / OSCILLATION_SCALE and period * RATE /
    DAMPING_SCALE rounded up, at least 1; ``period`` s, ``theta0`` rad.

    OMEGA and RATE bound the stiff terms' linearised rates on the smallest joint inertia m (half
    the smallest eigenvalue of M(theta0), as M varies by about 15 % across the stops): the
    stops' natural frequency OMEGA = sqrt(3 K / m) (a joint may touch its own stop and the
    coupled one, stiffness matrix eigenvalue up to 3 K) and the damping rate RATE = (3 B +
    viscous) / m, with the largest joint's viscous coefficient. The Coulomb friction adds no
    stiffness: its stick phase is a mode of the integration, not a steep force. At most
    2 * MAX_STEPS (simulate refuses that many).
    """
    stops, law = device.config.limits.stops, device.config.actuation.friction
    inertia = 0.5 * float(np.linalg.eigvalsh(device.phantom.mass_matrix(theta0)).min())
    stiffness = 3 * stops.stiffness if hard_stops else 0.0
    damping = (3 * stops.damping if hard_stops else 0.0) + (max(law.viscous) if friction else 0.0)
    need = max(period * math.sqrt(stiffness / inertia) / OSCILLATION_SCALE,
               period * damping / inertia / DAMPING_SCALE)
    need = min(need, 2.0 * MAX_STEPS)           # beyond the bound anyway (and no ceil of inf)
    return max(1, math.ceil(need * (1 - 1e-12)))


def servo_plant(device: Device, theta0: np.ndarray, period: float,
                friction: bool = True) -> tuple[Plant, int]:
    """A servo loop's plant at ``period`` s (the stops and saturation on, ``friction`` as asked)
    and its RK4 steps per period away from the stops, ceil(period / MAX_STEP); on a stop the
    steps contact_substeps asks at ``theta0`` (rad). What simulated drivers and the libHD
    stand-in step once a tick."""
    steps = max(1, math.ceil(period / MAX_STEP * (1 - 1e-12)))
    substeps = max(steps, contact_substeps(device, np.asarray(theta0, dtype=float), period, friction, True))
    return Plant(device, friction=friction, hard_stops=True, saturation=True, contact_step=period / substeps), steps


class Plant:
    """The device between two samples, for simulate(): ``saturate`` a command, then ``hold`` it
    over a sample period.

    M(theta) ddtheta + C dtheta + N(theta) = tau - tau_friction + tau_stops, with M including the
    rotors' reflected inertia (Pinocchio's crba and nonLinearEffects on the Phantom's mimic
    model: Phantom.forward_dynamics without its per-call checks), ``friction``
    (config.Friction, each joint its own law: viscous and Coulomb in motion; a joint at rest sticks
    while the torque that holds it is below its Coulomb torque, an exact mode of the integration) and
    ``hard_stops`` (Device.stop_torque); ``saturation`` the clip of commands: True for
    actuation.yaml's policy, "continuous" or "peak", False for none (Device.saturation_torque).
    ``contact_step`` (s): the longest RK4 step while a stop is engaged (contact_substeps).

    The integration (each of ``hold``'s steps): one RK4 step in the friction mode and the stops' contact of its
    start; a step in which a stop engages or releases, or a friction mode ends (a sliding joint
    reverses or stops, a stuck one breaks away), is cut at the first such event, located by
    regula falsi (Illinois) on its function and ended just past it; a reversing joint is set at
    rest there, and the rest of the step starts in the modes of that state (MAX_EVENTS per step).
    """

    def __init__(self, device: Device, *, friction: bool, hard_stops: bool, saturation: bool | str,
                 contact_step: float) -> None:
        self.friction, self.hard_stops, self.contact_step = bool(friction), bool(hard_stops), contact_step
        actuation = device.config.actuation
        self.limit = None if saturation is False else \
            list(actuation.limit(actuation.saturation if saturation is True else saturation))   # N m, the clip
        stops = device.config.limits.stops
        lower, upper = stops.bounds()
        self.bounds = list(zip(lower.tolist(), upper.tolist(), strict=True))     # rad, per stop coordinate
        self._flat_bounds = tuple(x for pair in self.bounds for x in pair)    # one unpacking per _margins
        self._stop_force = cast(StopForce, stops.force)                  # a float of floats
        law = actuation.friction
        self._coulomb = law.coulomb         # N m per joint, the breakaway torques
        #: (viscous1..3 N m s/rad, Coulomb1..3 N m), None without friction: one attribute lookup per evaluation
        self._law = (*law.viscous, *law.coulomb) if friction else None
        model = device.phantom.model
        # Pinocchio's model, data and inputs (filled in place), one tuple: one attribute lookup per evaluation
        self._pinocchio = (model, model.createData(), np.zeros(3), np.zeros(3))
        self._held_key: tuple | None = None                         # held()'s last state and its torques
        self._held: Sequence[float] = ()

    # (zip's strict= is left out where it runs per step: the keyword costs 0.2 us a call)

    # -- the public surface -----------------------------------------------------------
    def saturate(self, tau: List3) -> List3:
        """The command ``tau`` (N m) clipped to the saturation limit (in floats: np.clip costs more
        than the plant's step); ``tau`` itself without saturation."""
        limit = self.limit
        if limit is None:
            return tau
        return [-p if x < -p else p if x > p else x for x, p in zip(tau, limit)]  # noqa: B905

    def hold(self, q: List3, v: List3, tau: List3, period: float, count: int) -> tuple[List3, List3]:
        """The state (rad, rad/s) after ``period`` s under the torque ``tau`` (N m, held), in
        ``count`` equal steps (the class's doc); Diverged if it is not finite."""
        h = period / count
        for _ in range(count):
            q, v = self._advance(q, v, tau, h, 0)
        if not math.isfinite(sum(q) + sum(v)):   # NaN or inf anywhere
            raise Diverged
        return q, v

    def acceleration(self, q: List3, v: List3, tau: List3) -> Sequence[float]:
        """ddtheta (rad/s^2) at a state under the motor torque ``tau`` (N m), in the friction
        mode and stop contact of that state."""
        contact = self._contact(q, v, self._margins(q))
        return self._solve(tau, self._mode(q, v, tau, contact), contact, q, v)

    # -- the dynamics -------------------------------------------------------------------
    @overload
    def _solve(self, tau: Sequence[float], mode: Mode, contact: Contact, q: Sequence[float], v: Sequence[float],
               holding: Literal[False] = False) -> Sequence[float]: ...

    @overload
    def _solve(self, tau: Sequence[float], mode: Mode, contact: Contact, q: Sequence[float], v: Sequence[float],
               holding: Literal[True]) -> tuple[Sequence[float], Sequence[float]]: ...

    def _solve(self, tau: Sequence[float], mode: Mode, contact: Contact, q: Sequence[float], v: Sequence[float],
               holding: bool = False) -> Sequence[float] | tuple[Sequence[float], Sequence[float]]:
        """ddtheta (rad/s^2) in the friction ``mode`` (stuck joints: ddtheta = 0, held by whatever
        torque that takes) and the stops' ``contact`` (each engaged stop's spring and damper acting
        from its bound whichever side q is, so that a step is smooth up to the event that ends it);
        with ``holding``, (ddtheta, the friction torque holding each stuck joint, N m).
        M^-1 (tau - friction + stops - C dtheta - N). The arguments' order suits functools.partial
        (RK4's acceleration)."""
        # unrolled on Python floats: this runs four times per RK4 step, and Python's cost per
        # operation is what remains beside Pinocchio's (benchmarks/bench_plants.py)
        q0, q1, q2 = q
        v0, v1, v2 = v
        t0, t1, t2 = tau
        law = self._law
        if law is not None:
            d0, d1, d2, f0, f1, f2 = law        # viscous (damping) and Coulomb per joint
            m0, m1, m2 = mode
            t0 -= d0 * v0 + f0 * m0
            t1 -= d1 * v1 + f1 * m1
            t2 -= d2 * v2 + f2 * m2
        if contact is not None:
            stop_force = self._stop_force
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
        model, data, position, rate = self._pinocchio
        position[0], position[1], position[2] = q0, q1, q2
        rate[0], rate[1], rate[2] = v0, v1, v2
        b0, b1, b2 = pin.nonLinearEffects(model, data, position, rate).tolist()
        rhs = (t0 - b0, t1 - b1, t2 - b2)
        mass = pin.crba(model, data, position, pin.Convention.WORLD).tolist()    # DEVELOPERS.md
        if law is None or all(mode):
            solution = solve_spd(mass, rhs)
            if solution is None:  # M(theta) includes the rotors: positive definite at every finite theta
                raise Diverged
            return (solution, ()) if holding else solution
        return _constrained(mass, rhs, mode, holding)

    def _held_torque(self, q: List3, v: List3, tau: List3, mode: Mode, contact: Contact) -> Sequence[float]:
        """The torques (N m) holding the stuck joints of ``mode`` at a state, the last one
        remembered: the end of a step is where the next one starts, and a joint held still is
        held at the same state sample after sample."""
        key = (q, v, tau, mode, contact)
        if key != self._held_key:
            self._held_key = key
            self._held = self._solve(tau, mode, contact, q, v, True)[1]
        return self._held

    # -- modes and contact ----------------------------------------------------------------
    def _margins(self, q: Sequence[float]) -> List3:
        """Each stop coordinate's distance inside its range (rad; < 0 while the stop is engaged);
        empty without stops."""
        if not self.hard_stops:
            return []
        lo0, hi0, lo1, hi1, lo2, hi2, lo3, hi3 = self._flat_bounds
        q0, q1, q2 = q
        c = q1 - q2
        return [q0 - lo0 if q0 - lo0 < hi0 - q0 else hi0 - q0, q1 - lo1 if q1 - lo1 < hi1 - q1 else hi1 - q1,
                q2 - lo2 if q2 - lo2 < hi2 - q2 else hi2 - q2, c - lo3 if c - lo3 < hi3 - c else hi3 - c]

    def _contact(self, q: Sequence[float], v: Sequence[float], margin: List3) -> Contact:
        """The stops engaged at a state (Contact). ``margin``: _margins(q). A stop is engaged
        beyond its bound, and on it exactly if moving outwards (the step that located its contact
        may end on the boundary to the last bit)."""
        if not self.hard_stops or min(margin) > 0:
            return None
        q0, q1, q2 = q
        v0, v1, v2 = v
        out = []
        coordinates, rates = (q0, q1, q2, q1 - q2), (v0, v1, v2, v1 - v2)
        for c, rate, (lo, hi), m in zip(coordinates, rates, self.bounds, margin):  # noqa: B905
            lower = c - lo < hi - c
            out.append((lo if lower else hi) if m < 0 or (m == 0 and (rate < 0 if lower else rate > 0)) else None)
        return None if out == [None] * 4 else tuple(out)

    def _mode(self, q: List3, v: List3, tau: List3, contact: Contact) -> Mode:
        """The friction mode at a state: a moving joint slides; a joint at rest sticks if the
        torque that holds it is within its Coulomb torque, else it breaks away in the direction
        the net torque pushes it (released one at a time, the most overloaded first: the largest
        holding torque beyond its joint's Coulomb torque)."""
        if not self.friction:
            return (1, 1, 1)
        v0, v1, v2 = v
        if v0 and v1 and v2:
            return (1 if v0 > 0 else -1, 1 if v1 > 0 else -1, 1 if v2 > 0 else -1)
        return self._released(q, v, tau, contact)

    def _released(self, q: List3, v: List3, tau: List3, contact: Contact) -> Mode:
        """_mode's with a joint at rest: each stuck joint released or held in turn (_mode's doc)."""
        mode = [1 if x > 0 else -1 if x < 0 else 0 for x in v]
        while 0 in mode:
            holding = self._held_torque(q, v, tau, (mode[0], mode[1], mode[2]), contact)
            stuck = [i for i in range(3) if mode[i] == 0]
            coulomb = self._coulomb
            worst = max(range(len(stuck)), key=lambda k: abs(holding[k]) - coulomb[stuck[k]])
            if abs(holding[worst]) < coulomb[stuck[worst]]:        # at the Coulomb torque it breaks away
                break
            mode[stuck[worst]] = -1 if holding[worst] > 0 else 1
        return (mode[0], mode[1], mode[2])

    def _events(self, q: List3, v: List3, tau: List3, mode: Mode, contact: Contact, stop_signs: List3,
                margins: List3 | None = None) -> List3:
        """The event functions at a state, positive while the step's start's mode and contact hold:
        per joint the friction mode's slack (a sliding joint's rate along its direction, rad/s; a
        stuck joint's own Coulomb torque less the torque that holds it, N m; none without friction),
        then per stop coordinate its margin (rad) times ``stop_signs`` (+1 free, -1 engaged).
        ``margins``: _margins(q) if known."""
        if self.friction:
            coulomb = self._coulomb
            holding = iter(self._held_torque(q, v, tau, mode, contact) if not all(mode) else ())
            slack = [x * m if m else c - abs(next(holding)) for x, m, c in zip(v, mode, coulomb)]  # noqa: B905
        else:
            slack = []
        stop_part = self._margins(q) if margins is None else margins
        return slack + [m * sign for m, sign in zip(stop_part, stop_signs)]  # noqa: B905

    # -- the integration ------------------------------------------------------------------
    def _advance(self, q: List3, v: List3, tau: List3, h: float, depth: int) -> tuple[List3, List3]:
        """The state (rad, rad/s) after one step of ``h`` s under ``tau`` (N m), events located
        (the class's doc; ``depth`` of them already in this step), and while a stop is engaged in
        steps of at most ``contact_step``."""
        start_margins = self._margins(q)
        contact = self._contact(q, v, start_margins)
        mode = self._mode(q, v, tau, contact)
        if self.friction and not any(mode):    # every joint stuck (v = 0, ddtheta = 0) for the held torque
            return q, v
        acceleration = functools.partial(self._solve, tau, mode, contact)
        q_end, v_end = rk4_step(acceleration, q, v, h)
        end_margins = self._margins(q_end)
        if self.hard_stops and h > self.contact_step * (1 + 1e-9) and min(start_margins + end_margins) < 0:
            count = math.ceil(h / self.contact_step * (1 - 1e-12))    # a stop engaged: its substeps
            for _ in range(count):
                q, v = self._advance(q, v, tau, h / count, depth)
            return q, v
        # a free stop's margin, an engaged one's depth
        signs = [1.0] * len(start_margins) if contact is None else [1.0 if c is None else -1.0 for c in contact]
        end = self._events(q_end, v_end, tau, mode, contact, signs, end_margins)
        if not end or min(end) > 0 or depth >= MAX_EVENTS:
            return q_end, v_end
        return self._past_event(acceleration, q, v, tau, h, depth, mode, contact, signs, start_margins,
                                end, (q_end, v_end))

    def _past_event(self, acceleration: Callable, q: List3, v: List3, tau: List3, h: float, depth: int,
                    mode: Mode, contact: Contact, signs: List3, start_margins: List3, end: List3,
                    state_end: tuple[List3, List3]) -> tuple[List3, List3]:
        """_advance's step from (q, v) once an event function ``end`` is <= 0 at its end
        ``state_end``: the first event located, a sliding joint that reversed or stopped set at
        rest, and the rest of the step advanced from there."""
        q_end, v_end = state_end
        start = self._events(q, v, tau, mode, contact, signs, start_margins)
        shares = [a / (a - b) if b <= 0 < a else (0.0 if b <= 0 and a > 0 else 1.0)
                  for a, b in zip(start, end)]  # noqa: B905
        first = min(range(len(shares)), key=shares.__getitem__)
        share = shares[first]
        if share >= 1.0:                # nothing crossed from inside (a function at 0 at the start)
            return q_end, v_end
        if share <= 0.0:                # the mode ended at the start already
            share, q_end, v_end = 0.0, q, v
        else:
            share, q_end, v_end = self._locate(acceleration, q, v, tau, h, mode, contact, signs, first,
                                               (share, start[first], end[first]), (q_end, v_end))
        if first < len(mode) and self.friction and mode[first]:     # a sliding joint reversed or stopped: at rest
            v_end = list(v_end)
            v_end[first] = 0.0
        if share < 1.0:
            return self._advance(q_end, v_end, tau, (1.0 - share) * h, depth + 1)
        return q_end, v_end

    def _locate(self, acceleration: Callable, q: List3, v: List3, tau: List3, h: float, mode: Mode,
                contact: Contact, signs: List3, first: int, guess: tuple[float, float, float],
                end: tuple[List3, List3]) -> tuple[float, List3, List3]:
        """The event of the event function ``first`` within the step of ``h`` s from (q, v), by
        the Illinois variant of regula falsi bracketed in [low, high] (> 0 at low, <= 0 at high):
        (the share of the step at high, just past the event, and the state there). ``guess``:
        (the first share, the function at the start and at ``end``, the step's end state)."""
        share, at_low, at_high = guess
        q_end, v_end = end
        low, high, side = 0.0, 1.0, 0
        for _ in range(EVENT_ITERATIONS):
            q_try, v_try = rk4_step(acceleration, q, v, share * h)
            value = self._events(q_try, v_try, tau, mode, contact, signs)[first]
            if value > 0:
                low, at_low = share, value
                at_high, side = (at_high / 2 if side == 1 else at_high), 1
            else:
                high, at_high, q_end, v_end = share, value, q_try, v_try
                at_low, side = (at_low / 2 if side == -1 else at_low), -1
            if (high - low) * h <= EVENT_TOLERANCE:
                break
            share = low + (high - low) * at_low / (at_low - at_high)
        return high, q_end, v_end


#: Per friction mode with a stuck joint: (the sliding joints, the stuck ones), in order.
_PARTS = {mode: (tuple(i for i in range(3) if mode[i]), tuple(i for i in range(3) if not mode[i]))
          for mode in itertools.product((-1, 0, 1), repeat=3) if not all(mode)}


def _constrained(mass: list[list[float]], rhs: tuple[float, float, float], mode: Mode,
                 holding: bool) -> List3 | tuple[List3, List3]:
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
