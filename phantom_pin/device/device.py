"""Device: the physical PHANToM around its rigid body (stops, friction, motors, encoders).
Phantom stays the rigid body; this class holds the rest, from the same Config."""

from __future__ import annotations

import math
from typing import cast

import numpy as np

from phantom_pin._validation import as_states, finite_result, same_batch
from phantom_pin.config import Config
from phantom_pin.config.types import STOP_COORDINATES, Motor
from phantom_pin.dynamics._refusals import refusal
from phantom_pin.dynamics.phantom import Phantom
from phantom_pin.exceptions import InvalidInputError, MissingDataError
from phantom_pin.report import closed_form


class Device:
    """The PHANToM as a device: a Phantom plus its stops, friction, motors, encoders.

    ``Device(phantom)`` wraps a Phantom (``Device()`` the default one, ``Phantom()``);
    ``Device.from_model(model)`` a named model's (``Device(Phantom.from_model(model))``). A
    Description or a folder of one's own goes through its Phantom:
    ``Device(Phantom(description))``, ``Device(Phantom.from_folder(path))``; anything else given
    to the plain call is refused with InvalidInputError naming ``phantom`` and that call. The device numbers
    (``config.actuation`` and ``config.limits.stops``) come from the Phantom's own
    configuration, so the transmission ratios, and hence the currents and the armature, agree.

    Joint vectors are the report's theta1..theta3 (rad), rates rad/s, torques N m at the
    joint, currents A in the motor windings; tip positions and forces are in the report's
    frame s (m, N). Methods take one state (3,) or a batch (N, 3).

    Sign convention of the motors: a positive current drives its joint in the joint's
    positive direction, tau_i = ratio_i * torque_constant * i_i. A real amplifier may flip
    directions (mahilab/Phantom uses +1, -1, -1); that belongs to the driver, not here.

    A model whose motors, transmission or encoders are not public (the Touch: ``motor``,
    ``transmission_ratio`` and ``encoder`` are null in its actuation.yaml) still has its
    stops, friction and torque limits (``peak_torque``, the configuration's
    joint_torque_limit); what needs the missing data (currents, the continuous torque,
    encoder counts) raises MissingDataError, naming what the model lacks.

    Attributes: ``phantom`` (the rigid body), ``config`` (its Config: ``actuation`` and
    ``limits.stops`` hold the device's numbers, ``sources`` where they come from),
    ``ratios`` (3,), or None without public transmission ratios.
    """

    def __init__(self, phantom: Phantom | None = None) -> None:
        if phantom is None:
            phantom = Phantom()
        elif not isinstance(phantom, Phantom):
            raise refusal("Device", "a phantom_pin.Phantom or None", phantom, "phantom")
        self.phantom = phantom
        self.config: Config = phantom.config
        actuation = self.config.actuation
        #: joint angle = motor angle / ratio (the Phantom's actuation.yaml); None if not public
        self.ratios = None if actuation.ratios is None else np.array(actuation.ratios, dtype=float)
        encoder = actuation.encoder
        self._counts_per_radian = None if encoder is None or self.ratios is None else \
            self.ratios * encoder.cycles_per_revolution * encoder.counts_per_cycle / (2 * math.pi)

    @classmethod
    def from_model(cls, model: str) -> Device:
        """The named model ``model``'s device (phantom_pin.models()): ``Device(Phantom.from_model(model))``.
        InvalidInputError naming ``model`` for anything else."""
        return cls(Phantom.from_model(model))

    def require(self, section: str, needed_by: str) -> None:
        """MissingDataError naming ``needed_by`` unless the configuration has its ``section`` of
        actuation.yaml ("motor", "encoder", "transmission_ratio", as config.Actuation names them)."""
        if getattr(self.config.actuation, section) is None:
            raise MissingDataError(f"model {self.config.name} has no {section} data ({self.config.sources[section]})",
                                   argument=needed_by)

    # -- stops -----------------------------------------------------------------------
    def within_limits(self, theta: object) -> bool | np.ndarray:
        """True where theta (rad) is inside the real stops, boundaries included: each joint's
        stop interval, and the parallelogram's theta2 - theta3 <= theta2_minus_theta3_max and
        theta3 - theta2 <= theta3_minus_theta2_max. A bool for one state (3,), an (N,) bool
        array for a batch (N, 3)."""
        q, batch = as_states(theta, "theta")
        inside = self._inside(q)
        return inside if batch else bool(inside)

    def _inside(self, theta: np.ndarray) -> np.ndarray:
        """within_limits of postures (..., 3) rad, checked: a bool array (...)."""
        return np.all(self.config.limits.stops.penetration(theta) == 0, axis=-1)

    def reachable(self, position: object) -> bool | np.ndarray:
        """True where the tip can reach ``position`` (m, the report's frame s) with every joint
        inside the real stops: a bool for one position (3,), a bool array of the batch's shape
        for (..., 3).

        Candidates are the report's inverse kinematics (eqs 11-20, closed_form, with this
        device's Phantom parameters) on both elbow branches, and the same with axis 1 turned
        by pi and the arm reaching back over it ((theta1 + pi, pi - theta2, -theta3) puts the
        tip at the same point), each also shifted by 2 pi in theta2 and theta3.
        """
        target, batch = as_states(position, "position")
        shape = target.shape[:-1]
        target = target.reshape(-1, 3)
        p = self.config.kinematics
        shoulder = np.array([0.0, p.l2, -p.l1])  # in frame s (eqs 4-5)
        with np.errstate(over="ignore"):          # a huge target is simply out of reach (inf)
            distance = np.linalg.norm(target - shoulder, axis=-1)
        shell = (distance > abs(p.l1 - p.l2)) & (distance < p.l1 + p.l2)
        found = np.zeros(len(target), dtype=bool)
        if shell.any():
            wraps = 2 * np.pi * np.array([[0, k2, k3] for k2 in (-1, 0, 1) for k3 in (-1, 0, 1)])
            for branch in ("report", "other"):
                front = closed_form.inverse_kinematics(target[shell], p, branch)
                back = np.stack([front[:, 0] - np.sign(front[:, 0]) * np.pi,
                                 np.pi - front[:, 1], -front[:, 2]], axis=-1)
                for theta in (front, back):
                    candidates = theta[:, None, :] + wraps           # (n, 9, 3)
                    found[shell] |= self._inside(candidates.reshape(-1, 3)).reshape(-1, 9).any(axis=1)
        return found.reshape(shape) if batch else bool(found[0])

    def stop_energy(self, theta: object) -> np.ndarray:
        """Potential energy of the stop springs (J): K/2 * sum of squared penetrations of
        theta1, theta2, theta3 and theta2 - theta3 beyond their stops; zero inside."""
        q, _ = as_states(theta, "theta")
        with np.errstate(over="ignore", invalid="ignore"):
            stops = self.config.limits.stops
            energy = 0.5 * stops.stiffness * np.sum(stops.penetration(q) ** 2, axis=-1)
        return finite_result(energy, "theta")

    def stop_torque(self, theta: object, dtheta: object) -> np.ndarray:
        """Torque of the hard stops on the joints (N m): (..., 3).

        Each stop coordinate c (theta1, theta2, theta3, theta2 - theta3) beyond its stop by
        the penetration p pushes back with K p + B dc/dt along dc/dtheta: the spring is
        -grad(stop_energy), and the damper acts only while penetrating. A coupled stop
        therefore acts on theta2 and theta3 equally and oppositely. Its power is
        -B (dc/dt)^2 <= 0 plus the spring's exchange with stop_energy, so stops never add
        energy. Where one stop is active this is mahilab/Phantom's tau = K (limit - theta)
        - B dtheta (there the damping of a coupled stop acts on theta2 - theta3's rate).
        """
        q, _ = as_states(theta, "theta")
        v, _ = as_states(dtheta, "dtheta")
        same_batch(("theta", "dtheta"), q, v)
        with np.errstate(over="ignore", invalid="ignore"):
            torque = self._stop_torque(q, v)
        return finite_result(torque, "theta, dtheta")

    def _stop_torque(self, theta: np.ndarray, dtheta: np.ndarray) -> np.ndarray:
        stops = self.config.limits.stops
        depth = self.config.limits.stops.penetration(theta)
        force = stops.force(depth, dtheta @ STOP_COORDINATES.T)
        return -force @ STOP_COORDINATES

    # -- friction --------------------------------------------------------------------
    def friction(self, dtheta: object) -> np.ndarray:
        """Sliding friction torque (N m) of each joint at rates dtheta (rad/s): (..., 3).

        tau_f,i = viscous[i] * dtheta_i + coulomb[i] * sign(dtheta_i), each joint i its own law
        (N m s/rad, N m), with the sign of dtheta: it opposes motion, M ddtheta + C dtheta + N +
        tau_f = tau. At rest (dtheta = 0) it returns 0: a joint at rest sticks, held by whatever
        torque that takes up to its ``coulomb`` (the breakaway torque), which depends on the
        load; phantom_pin.simulate integrates that (config.Friction).
        """
        v, _ = as_states(dtheta, "dtheta")
        return np.asarray(self.config.actuation.friction.torque(v))

    # -- motors ----------------------------------------------------------------------
    @property
    def continuous_torque(self) -> np.ndarray:
        """Joint torque (N m) of each motor's max. continuous torque: max_continuous_torque * ratio.
        MissingDataError without public motor data."""
        self.require("motor", "continuous_torque")
        return np.array(self.config.actuation.effort)

    @property
    def peak_torque(self) -> np.ndarray:
        """The most torque (N m) each joint's drive gives: the motor's stall_torque * ratio, or
        the configuration's joint_torque_limit without public motor data."""
        return np.array(self.config.actuation.peak)

    @property
    def saturation_torque(self) -> np.ndarray:
        """Where simulate() and the MJCF clip commanded torques (N m): the continuous or the peak
        torque, by actuation.yaml's ``saturation`` (config.Actuation.saturation_torque)."""
        return np.array(self.config.actuation.saturation_torque)

    def _limit(self, continuous: object) -> np.ndarray:
        """The continuous or the peak torque limit (N m), as the saturation policies read them
        (config.Actuation.limit): a model without public motor data has one limit, its
        joint_torque_limit, for both."""
        if not isinstance(continuous, (bool, np.bool_)):
            raise InvalidInputError(f"expected True or False, got {continuous!r}", argument="continuous")
        return np.array(self.config.actuation.limit("continuous" if continuous else "peak"))

    def _drive(self, needed_by: str) -> tuple[np.ndarray, Motor]:
        """(the transmission ratios, the motor); MissingDataError naming ``needed_by`` without
        public motor data (the Config gives the ratios and the motor together or neither)."""
        self.require("motor", needed_by)
        return cast(np.ndarray, self.ratios), cast(Motor, self.config.actuation.motor)

    def motor_currents(self, tau: object) -> np.ndarray:
        """Winding currents (A) that give joint torques tau (N m): tau / (ratio * torque_constant).
        MissingDataError without public motor data."""
        ratios, motor = self._drive("motor_currents")
        t, _ = as_states(tau, "tau")
        with np.errstate(over="ignore"):
            currents = t / (ratios * motor.torque_constant)
        return finite_result(currents, "tau")

    def joint_torques(self, currents: object) -> np.ndarray:
        """Joint torques (N m) of winding currents (A): ratio * torque_constant * currents.
        MissingDataError without public motor data."""
        ratios, motor = self._drive("joint_torques")
        i, _ = as_states(currents, "currents")
        with np.errstate(over="ignore"):
            torques = i * ratios * motor.torque_constant
        return finite_result(torques, "currents")

    def available_torque(self, theta: object, continuous: bool = True) -> tuple[np.ndarray, np.ndarray]:
        """Joint torques (N m) left for rendering forces at theta after holding gravity.

        Returns (lower, upper), each (..., 3): the motors can add any tau_render with
        lower <= tau_render <= upper while also compensating gravity N(theta), i.e.
        -limit - N <= tau_render <= limit - N, where limit is the continuous torque
        (``continuous=True``) or the peak torque (a model without public motor data, the Touch:
        its joint_torque_limit for both, as simulate's saturation). Where gravity alone exceeds
        the limit, upper < 0 or lower > 0.
        """
        gravity = self.phantom.gravity(theta)
        limit = self._limit(continuous)
        return -limit - gravity, limit - gravity

    def tip_jacobian(self, theta: object) -> np.ndarray:
        """J_p = d(tip position in frame s)/d(theta): (..., 3, 3), m/rad. A tip force F (N,
        frame s) needs the joint torques J_p^T F (N m)."""
        rotation = self.phantom.forward_kinematics(theta)[..., :3, :3]
        return rotation @ self.phantom.body_jacobian(theta)[..., :3, :]

    def tip_force_capacity(self, theta: object, direction: object, continuous: bool = True) -> np.ndarray:
        """The largest tip force (N) the device can render along ``direction`` (frame s,
        normalised here) at theta while holding gravity: (...,).

        The force F = f u needs the joint torques J_p^T F (J_p the tip's position Jacobian
        in s); f is the largest f >= 0 within available_torque(theta, continuous); 0 where
        gravity alone exceeds a limit. Joints the force does not load (to 1e-12 of the
        Jacobian's norm) set no bound: inf where none does (a force along the straight arm is
        carried by the structure).
        """
        q, _ = as_states(theta, "theta")
        u, _ = as_states(direction, "direction")
        if q.ndim > 1 and u.ndim > 1 and q.shape != u.shape:
            raise InvalidInputError(f"theta {q.shape} and direction {u.shape}: a batch of each must have "
                                    "the same shape")
        scale = np.abs(u).max(axis=-1, keepdims=True)
        if np.any(scale == 0):
            raise InvalidInputError("must not be the zero vector", argument="direction")
        u = u / scale                                         # no overflow in the norm
        u = u / np.linalg.norm(u, axis=-1, keepdims=True)
        lower, upper = self.available_torque(q, continuous)
        jacobian = self.tip_jacobian(q)
        per_force = np.einsum("...ji,...j->...i", jacobian, u)  # N m per N
        # a joint the force does not load (to rounding: along the straight arm) sets no bound
        tiny = 1e-12 * np.linalg.norm(jacobian, axis=(-2, -1))[..., None]
        with np.errstate(divide="ignore", invalid="ignore"):
            bound = np.where(per_force > tiny, upper / per_force,
                             np.where(per_force < -tiny, lower / per_force, np.inf))
        return np.clip(bound.min(axis=-1), 0.0, None)

    # -- encoders --------------------------------------------------------------------
    @property
    def encoder_resolution(self) -> np.ndarray:
        """Joint angle of one encoder count (rad): 2 pi / (ratio * cycles_per_revolution *
        counts_per_cycle), (3,). MissingDataError without public encoder data."""
        self.require("encoder", "encoder_resolution")
        return 1.0 / self.counts_per_radian

    @property
    def counts_per_radian(self) -> np.ndarray:
        """Encoder counts per radian of each joint: ratio * cycles_per_revolution *
        counts_per_cycle / (2 pi), (3,). MissingDataError without public encoder data."""
        self.require("encoder", "counts_per_radian")
        return cast(np.ndarray, self._counts_per_radian)    # set with the encoder (which comes with the ratios)

    def encoder_counts(self, theta: object) -> np.ndarray:
        """Encoder counts (int64) at theta (rad): round(theta * ratio * cycles * counts_per_cycle
        / (2 pi)). Count 0 is the report's zero configuration; a real device reads counts
        from wherever it was switched on and needs a calibration offset."""
        self.require("encoder", "encoder_counts")
        q, _ = as_states(theta, "theta")
        with np.errstate(over="ignore"):          # refused below
            counts = np.rint(q * self.counts_per_radian)
        if np.abs(counts).max() >= 2.0**62:
            raise InvalidInputError("too large, its encoder counts overflow a 64-bit integer", argument="theta")
        return counts.astype(np.int64)

    def encoder_theta(self, counts: object) -> np.ndarray:
        """Joint angles (rad) of encoder counts: counts * encoder_resolution."""
        self.require("encoder", "encoder_theta")
        c, _ = as_states(counts, "counts")
        return c * self.encoder_resolution

    def tip_resolution(self, theta: object) -> np.ndarray:
        """Tip displacement (m) of one encoder count of each joint at theta: (..., 3),
        |column i of the tip's position Jacobian| * encoder_resolution[i]."""
        return np.linalg.norm(self.tip_jacobian(theta), axis=-2) * self.encoder_resolution
