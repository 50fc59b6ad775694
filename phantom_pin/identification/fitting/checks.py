"""What decides whether a log can be identified and a fit written: the refusals that need no fit
(run first, before any costly stage) and the verdict on a fit (``problems``, one line each).

Before the fit: angles that are no posture of the arm and torques that are no joint torques of a
desk-top arm (before any arithmetic on them), constant torques, too little motion, and the logged
torques' size and sign against the prior model's prediction along the motion (``torque_problems``:
a log in mN m, a joint's flipped sign or another joint's ratio show there without any fit).
After the fit: a model that predicts the log worse than the prior, angles beyond the stops,
torques unrelated to the motion, the same size and sign check, negative friction, a physical
projection that moves an estimate far or flips its sign, a joint's gain that is negative
(amplifier polarity) or outside GAIN_BOUNDS (a unit, another joint's ratio).
"""

from __future__ import annotations

import numpy as np

from phantom_pin.dynamics.phantom import Phantom
from phantom_pin.exceptions import LogError
from phantom_pin.identification.data.io import Log
from phantom_pin.identification.fitting.filtering import EDGE
from phantom_pin.identification.fitting.fit import Fit
from phantom_pin.identification.structure.structures import Structure

#: Angles further than this beyond the stops (rad) are no posture of the arm: refused before
#: the fit, as simulate refuses such a start.
NO_POSTURE = 2 * np.pi
#: Torques above this (N m) are no joint torque of a desk-top haptic arm (the Premium 1.5's
#: peak is 1.7 N m): refused before the fit (1e300 overflowed its arithmetic).
MAX_TORQUE = 1e3
#: Fewest kept samples, and fewest at which each joint moves (filtering.MIN_SPEED).
MIN_SAMPLES = 50
#: Largest residual RMS of a joint, as a share of its torque RMS, that a usable log leaves
#: (a device's log leaves 0.3-3 %; torques unrelated to the motion, 50-100 %).
MAX_RESIDUAL_SHARE = 0.15
#: The logged torques fit the model best scaled by s: refused outside these bounds (a unit).
TORQUE_SCALE = (1 / 3, 3.0)
#: Before the fit, a joint's logged torques are compared with the prior's prediction only where
#: they follow its shape: a correlation of at least this (the sign aside; a device's log and a
#: prior off by the CAD model's 5-30 % correlate above 0.98, torques unrelated to the motion near 0).
FOLLOWS = 0.9
#: A scale between these is named as milli-newton metres (1000 +- a prior's error).
MILLI = (300.0, 3000.0)
#: A relative gain outside these bounds is no tolerance but a mistake (a unit, another joint's
#: ratio): refused; a negative one is a flipped amplifier.
GAIN_BOUNDS = (0.5, 2.0)
#: A base parameter the physical projection moves by more than this many standard deviations
#: and more than SHIFT_SHARE of its value means the estimate is not of a physical arm.
MAX_SHIFT_SIGMA, SHIFT_SHARE = 10.0, 0.1
#: Angles further than this (rad) beyond the stops are not of the arm.
BEYOND_STOPS = 0.2


class RefusedError(LogError):
    """A log whose fit should not be written (``problems``: one line each, most telling first)."""

    def __init__(self, problems: tuple[str, ...] | list[str]) -> None:
        self.problems = tuple(problems)
        super().__init__(f"{refusal(self.problems)}; not identified (accept=True keeps the fit anyway)")


def refusal(problems: tuple[str, ...] | list[str]) -> str:
    """The first problem, and how many more there are."""
    more = f" (and {len(problems) - 1} more)" if len(problems) > 1 else ""
    return f"{problems[0]}{more}"


#: The stop coordinates' names, in the order of config.types.STOP_COORDINATES (the fourth: the
#: parallelogram's coupled stop).
STOP_NAMES = ("theta1", "theta2", "theta3", "theta2 - theta3")

def refuse_log(log: Log, phantom: Phantom) -> None:
    """LogError for a log no arithmetic should touch: angles more than NO_POSTURE beyond the
    stops (degrees?), torques above MAX_TORQUE N m (mN m?), a joint's torque constant throughout."""
    beyond = np.abs(phantom.config.limits.stops.penetration(log.theta)).max(axis=0)
    if (beyond > NO_POSTURE).any():  # before any arithmetic on them (1e300 rad: no SVD converges)
        j = int(np.argmax(beyond))
        raise LogError(f"{STOP_NAMES[j]}: the log's angles reach {beyond[j]:.3g} rad beyond the stops, more than a "
                       "turn: no posture of the arm; are they in degrees? (the log holds the report's theta in rad, "
                       "or use --convention openhaptics)")
    huge = np.abs(log.tau).max(axis=0)
    if (huge > MAX_TORQUE).any():
        j = int(np.argmax(huge))
        raise LogError(f"tau{j + 1}: the log's torques reach {huge[j]:.3g} N m, more than {MAX_TORQUE:g} N m: not "
                       "joint torques in N m (mN m? use --convention openhaptics for OpenHaptics' joint torques)")
    constant = [f"tau{j + 1}" for j in range(3) if np.ptp(log.tau[:, j]) == 0]
    if constant:
        raise LogError(f"{', '.join(constant)}: constant torque{'s' if len(constant) > 1 else ''} over the whole "
                       "log: nothing to identify (the log must hold the torques commanded during the motion)")


def refuse_motion(moving: np.ndarray, cutoff: float, min_speed: float) -> None:
    """LogError when the filtered log keeps fewer than MIN_SAMPLES samples, or a joint moves
    faster than ``min_speed`` (rad/s) at fewer (``moving`` (N, 3): filtering.Samples.moving)."""
    if len(moving) < MIN_SAMPLES:
        raise LogError(f"too short: {len(moving)} samples after filtering at {cutoff:g} Hz and cutting "
                       f"{EDGE} s at each end (need {MIN_SAMPLES})")
    if (moving.sum(axis=0) < MIN_SAMPLES).any():
        still = ", ".join(str(j + 1) for j in np.flatnonzero(moving.sum(axis=0) < MIN_SAMPLES))
        raise LogError(f"too little motion: joint(s) {still} move faster than {min_speed:g} rad/s in fewer than "
                       f"{MIN_SAMPLES} samples filtered at {cutoff:g} Hz; log an excitation trajectory (phantom-pin "
                       "excite), filter less, or lower --min-speed")


def torque_problems(y: np.ndarray, prior: np.ndarray,
                    follows: np.ndarray) -> tuple[list[str], list[str], list[int]]:
    """The logged torques' size and sign against the prior's prediction along the motion: ``y``
    and ``prior`` (N, 3; N m, the logged and the prior model's torques less the known ones, over
    the fitted equations), ``follows`` (3,) whether each joint's torques follow the motion at all
    (else their size says nothing). Returns (one line per joint whose scale or sign is off, most
    telling first; one line when every joint's is: the unit; the joints (0-2) whose is off)."""
    sizes = (y * prior).sum(axis=0) / np.maximum((prior * prior).sum(axis=0), 1e-300)    # per joint
    wrong = [j for j in range(3) if not TORQUE_SCALE[0] <= sizes[j] <= TORQUE_SCALE[1]]
    if len(wrong) == 3:
        size = float((y * prior).sum() / (prior * prior).sum())
        unit = ("; are their signs flipped (amplifier polarity)?" if size < 0 else
                ": in mN m? (the log holds N m at the joint; OpenHaptics' joint torques in mN m: --convention "
                "openhaptics)" if MILLI[0] <= size <= MILLI[1] else
                "; are they in another unit (N m at the joint, not mN m or motor torques)?")
        return [], [f"tau: the logged torques are {size:.3g} times the model's prediction along the motion"
                    + unit], wrong
    return [f"tau{j + 1}: the logged torques are {sizes[j]:.3g} times the model's prediction along the motion"
            + (f": tau{j + 1}'s sign is flipped (amplifier polarity)?" if sizes[j] < 0 else
               "; in another unit, or converted with another joint's transmission ratio? The log must hold joint "
               "torques (N m at the joint: motor torque x ratio)") for j in reversed(wrong) if follows[j]], [], wrong


def before_fit(y: np.ndarray, prior: np.ndarray) -> list[str]:
    """The torque_problems visible without any fit: ``y`` and ``prior`` as there; a joint's
    torques follow the motion where they correlate with the prior's by FOLLOWS or more."""
    correlation = np.abs((y * prior).sum(axis=0)) / np.maximum(
        np.sqrt((y * y).sum(axis=0) * (prior * prior).sum(axis=0)), 1e-300)
    joints, unit, _ = torque_problems(y, prior, correlation >= FOLLOWS)
    return joints + unit if (correlation >= FOLLOWS).all() or joints else []


def problems(fit: Fit, structure: Structure, phi: np.ndarray, y: np.ndarray, log: Log, phantom: Phantom) -> list[str]:
    """Why ``fit`` should not be written (module doc), most telling first; ``phi`` (N, 3, P) the
    regressor over the fitted equations, ``y`` the logged torques less the known ones (N m,
    before the gains' correction)."""
    found = []
    worse = fit.prediction.worse()
    if worse is not None:
        found.append(worse)
    beyond = float(np.abs(phantom.config.limits.stops.penetration(log.theta)).max())
    if beyond > BEYOND_STOPS:
        found.append(f"theta: the log's angles reach {beyond:.3g} rad beyond the stops; are they in degrees, or "
                     "in another convention? (the log holds the report's theta in rad, or use --convention "
                     "openhaptics)")
    share = fit.log_rms / fit.torque_rms      # the log alone's: the prior may pull a wrong log's fit
    follows = share.max() <= MAX_RESIDUAL_SHARE        # else the torques' sizes say nothing per joint
    if not follows:
        found.append("the fit leaves " + ", ".join(f"{100 * s:.0f} %" for s in share) + " of the torque RMS "
                     f"(at most {100 * MAX_RESIDUAL_SHARE:.0f} %): the torques do not follow the motion; check "
                     "that theta and tau are the same samples, in rad and N m")
    expected = phi @ (structure.matrix @ structure.prior + structure.offset)
    joints, unit, wrong = torque_problems(y, expected, np.full(3, follows))
    found = joints + found + unit + _fitted(fit, structure)
    for j in (1, 2) if len(wrong) < 3 and follows else ():    # the gains of joints whose size is plausible
        if j in wrong or GAIN_BOUNDS[0] <= fit.gains[j] <= GAIN_BOUNDS[1]:
            continue
        found.insert(0, f"tau{j + 1} is {1 / fit.gains[j]:.3g} times joint 1's torque scale (gain "
                     f"{fit.gains[j]:.3g}" + (f"): tau{j + 1}'s sign is flipped (amplifier polarity)" if
                                              fit.gains[j] < 0 else
                                              f", outside {GAIN_BOUNDS[0]:g}-{GAIN_BOUNDS[1]:g}: no drive's "
                                              "tolerance): converted with another joint's transmission ratio or "
                                              "unit? The log must hold joint torques (N m at the joint)"))
    return found


def _fitted(fit: Fit, structure: Structure) -> list[str]:
    """The problems of the estimate itself: negative friction, a projection that moves a base
    parameter far (MAX_SHIFT_SIGMA and SHIFT_SHARE) or flips its sign."""
    found = []
    values, sigma = fit.friction
    negative = [name for name, v, s in zip(structure.names[-6:], values, sigma) if v < -3 * s]
    if negative:
        found.append(f"negative friction ({', '.join(negative)}): check the torque signs, units and "
                     "transmission ratios (friction is written as 0 or more)")
    moved = np.abs(fit.written - fit.beta)
    far = np.flatnonzero((moved > MAX_SHIFT_SIGMA * fit.sigma) & (moved > SHIFT_SHARE * np.abs(fit.beta)))
    if far.size:
        k = far[np.argmax((moved / fit.sigma)[far])]
        flipped = np.sign(fit.written[k]) != np.sign(fit.beta[k])
        name = structure.base_names[k].split(" = ")[0]
        name = name if len(name) <= 40 else name[:40].rsplit(" ", 1)[0] + " ..."
        found.append(f"the nearest physical parameters move beta{k + 1} ({name}) from "
                     f"{fit.beta[k]:.4g} to {fit.written[k]:.4g} {fit.units[k]} ({moved[k] / fit.sigma[k]:.3g} "
                     f"standard deviations{', a flipped sign' if flipped else ''}): the estimate is not of a "
                     "physical arm; check torque signs, units and transmission ratios")
    return found
