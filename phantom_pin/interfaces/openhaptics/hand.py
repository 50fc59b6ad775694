"""What a hand feels through the servo loop, measured on the simulated device (docs/feel.md).

The device is simulate()'s plant (device.plant.Plant) stepped at 1 kHz with the command of each
tick held over it (zero-order hold), the compensator (``Compensator``, in joint-torque mode:
the same torques as its force mode away from singular postures) fed the tick's angles rounded
to the encoder's counts where the model has public encoder data (the Premium 1.5; the Touch's
are not public: exact angles), as OpenHaptics' loop gives them. The hand acts at the tip (the
gimbal centre) through J_p^T F_hand. Three experiments:

- ``apparent_mass``: a constant hand force f along a direction u from rest; the tip's
  displacement along u over a window, fitted by d = a t^2 / 2 (+ v0 t + d0), gives the mass the
  hand feels, f / a (kg). Without friction in the plant, to see the inertia alone.
- ``backdrive``: the hand drags the tip along u at a constant speed through a stiff coupling
  (a spring-damper to a target moving at ``speed``); the mean coupling force along u over the
  steady part is the backdrive force (N).
- ``rest_drift``: no hand, from rest: how far the tip wanders (m).
- ``wall``: a virtual wall F = -K (n . x - w) n (plus a damping B) rendered in the loop where
  the tip is beyond the plane, the hand pressing into it with a constant force: the wall is
  stable at K if the tip's oscillation about its rest, in the last half of the run, stays below
  ``amplitude`` (m); ``stiffest_wall`` bisects K.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from phantom_pin.exceptions import InvalidInputError

#: The servo period (s).
PERIOD = 1e-3


@dataclasses.dataclass
class Run:
    """One experiment's samples: t (s), tip (m, frame s), the hand's force (N, frame s)."""

    t: np.ndarray
    tip: np.ndarray
    hand: np.ndarray


def run(compensator, theta0, duration, hand, friction=True, wall=None, noise=0.0) -> Run:
    """Run the device for ``duration`` s from rest at ``theta0`` (rad) with ``compensator``
    (None: no compensation) and the hand ``hand(t, tip, tip_velocity) -> F`` (N, frame s);
    ``wall`` (n, w, K, B) adds the virtual wall's force to the command; ``noise`` (rad) is the
    standard deviation of a seeded Gaussian noise on the angles before their rounding to counts
    (an encoder's transitions flicker). Returns a Run."""
    from phantom_pin.device.plant import servo_plant

    device = compensator.device if compensator is not None else None
    if device is None:
        raise InvalidInputError("expected a Compensator (its device is the plant's)", argument="compensator")
    plant, steps = servo_plant(device, np.array(theta0, dtype=float), PERIOD, friction)
    quantized = device.config.actuation.encoder is not None
    sign = compensator._sign
    q, v = list(map(float, theta0)), [0.0, 0.0, 0.0]
    rng = np.random.default_rng(0)
    count = int(round(duration / PERIOD))
    t, tips, hands = np.arange(count) * PERIOD, np.empty((count, 3)), np.empty((count, 3))
    for k in range(count):
        theta = np.array(q)
        seen = theta + (rng.normal(0.0, noise, 3) if noise else 0.0)
        seen = device.encoder_theta(device.encoder_counts(seen)) if quantized else seen
        jacobian = device.tip_jacobian(theta)
        tip = device.phantom.forward_kinematics(theta)[:3, 3]
        force = hand(t[k], tip, jacobian @ np.array(v))
        tau = np.array(compensator(seen * sign)) * sign / 1000.0
        if wall is not None:
            normal, offset, stiffness, damping = wall
            depth = float(normal @ device.phantom.forward_kinematics(seen)[:3, 3] - offset)
            if depth > 0:
                rate = float(normal @ (jacobian @ compensator.estimator.rate))
                tau += jacobian.T @ (-(stiffness * depth + damping * rate) * normal)
        tips[k], hands[k] = tip, force
        applied = np.array(plant.saturate(tau.tolist())) + jacobian.T @ force     # the hand is not the motors'
        q, v = plant.hold(q, v, applied.tolist(), PERIOD, steps)
    return Run(t, tips, hands)


def apparent_mass(compensator, theta0, direction, force=0.02, window=(0.04, 0.1)) -> float:
    """The mass (kg) the hand feels along ``direction`` (frame s) pushing with ``force`` N from
    rest at ``theta0``, friction off in the plant (module doc)."""
    u = np.asarray(direction, float) / np.linalg.norm(direction)
    samples = run(compensator, theta0, window[1], lambda t, x, dx: force * u, friction=False)
    keep = samples.t >= window[0]
    along = (samples.tip[keep] - samples.tip[0]) @ u
    a = 2.0 * np.polyfit(samples.t[keep], along, 2)[0]
    return force / a


def backdrive(compensator, theta0, direction, speed=0.02, duration=0.5, stiffness=2000.0, damping=20.0) -> float:
    """The mean force (N) the hand needs along ``direction`` (frame s) to drag the tip at
    ``speed`` m/s, over the second half of ``duration`` s (module doc)."""
    u = np.asarray(direction, float) / np.linalg.norm(direction)
    start = None

    def hand(t, tip, velocity):
        nonlocal start
        start = tip if start is None else start
        target = start + speed * t * u
        return stiffness * (target - tip) + damping * (speed * u - velocity)

    samples = run(compensator, theta0, duration, hand)
    steady = samples.t >= duration / 2
    return float((samples.hand[steady] @ u).mean())


def rest_drift(compensator, theta0, duration=2.0, noise=2e-4) -> float:
    """How far (m) the tip wanders in ``duration`` s from rest at ``theta0`` with no hand, the
    angles seen with ``noise`` (rad): what a compensation that pushes a resting joint on noise
    does (the dead band's purpose)."""
    samples = run(compensator, theta0, duration, lambda t, x, dx: np.zeros(3), noise=noise)
    return float(np.linalg.norm(samples.tip - samples.tip[0], axis=1).max())


def wall_is_stable(compensator, theta0, normal, stiffness, damping=0.0, push=0.5, duration=1.0,
                   amplitude=1e-4) -> bool:
    """Whether the wall of ``stiffness`` N/m (and ``damping`` N s/m) through the tip at theta0,
    normal ``normal`` (frame s, the wall's inside beyond it), holds the hand's ``push`` N still:
    the tip's depth varies by less than ``amplitude`` m (peak to peak) over the last quarter of
    ``duration`` s (an oscillation that has not died out by then is sustained)."""
    for name, value in (("stiffness", stiffness), ("damping", damping)):
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0 <= value < math.inf:
            raise InvalidInputError(f"expected a finite number >= 0, got {value!r}", argument=name)
    n = np.asarray(normal, float) / np.linalg.norm(normal)
    offset = float(n @ compensator.device.phantom.forward_kinematics(np.asarray(theta0, float))[:3, 3])
    samples = run(compensator, theta0, duration, lambda t, x, dx: push * n, wall=(n, offset, stiffness, damping))
    depth = samples.tip[samples.t >= 0.75 * duration] @ n
    return bool(np.isfinite(depth).all() and depth.max() - depth.min() < amplitude)


def stiffest_wall(make, theta0, normal, low=100.0, high=1e5, rounds=12, **options) -> float:
    """The largest stable stiffness (N/m) by bisection in log between ``low`` and ``high``,
    ``make()`` a fresh Compensator for each trial (its estimates start at rest)."""
    if not wall_is_stable(make(), theta0, normal, low, **options):
        return 0.0
    for _ in range(rounds):
        middle = math.sqrt(low * high)
        if wall_is_stable(make(), theta0, normal, middle, **options):
            low = middle
        else:
            high = middle
    return low
