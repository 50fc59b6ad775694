"""The force a driver must send so that the stylus floats, and a user's force on top: the
computation of ``phantom-pin ros2 --driver``, without ROS.

Every public Touch driver takes a Cartesian force F (N) and sends it as OpenHaptics'
HD_CURRENT_FORCE, which the device renders at the gimbal centre (the tool frame t, URDF frame
``tip``) as the joint torques J_p(theta)^T F, J_p the tip's position Jacobian in frame s
(m/rad; OpenHaptics' axes are frame s's: phantom_pin.interfaces.profiles). So

    F = F_user + F_comp,   J_p(theta)^T F_comp = G(theta, g) [+ tau_f(dtheta)]

with G the device's gravity torques (N m; the stylus's at the gimbal angles g included) and
tau_f the model's friction law at a filtered joint rate (``compensate``). F_comp = J_p^-T (G +
tau_f) by the singular values of J_p; where the smallest, sigma_min, falls below SINGULAR
(m/rad), a damped inverse (variable damping lambda^2 = SINGULAR^2 (1 - (sigma_min /
SINGULAR)^2)) keeps the force bounded, and ``Rendered.singular`` says so.

The total is then clamped, its direction kept, to the lowest of: the driver's own clamp (N),
``max_force`` (N), and what the motors can give (the largest scale at which every joint torque
J_p^T F lies within the device's saturation torque, Device.saturation_torque). Nothing here
returns a non-finite force: a non-finite input raises InvalidInputError naming it.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence

import numpy as np
import pinocchio as pin

from phantom_pin.config.types import Friction
from phantom_pin.device import estimator
from phantom_pin.device.device import Device
from phantom_pin.device.estimator import Estimator
from phantom_pin.device.thermal import TorqueBudget
from phantom_pin.dynamics.phantom import Phantom
from phantom_pin.exceptions import InvalidInputError
from phantom_pin.interfaces.profiles import Profile

__all__ = ["Renderer", "Frames", "Rendered"]

#: Three numbers: a sequence or a (3,) array.
Vector = Sequence[float] | np.ndarray
#: The smallest singular value of J_p (m/rad) below which the inverse is damped: 2 mm/rad, a
#: lever 1.5 % of the Touch's arm (2000 seeded postures inside its stops reach 2.8 mm/rad, over joint 1).
SINGULAR = 0.002
#: What may be compensated (``compensate``): inertia is a share ``kappa`` of M ddtheta + C dtheta.
TERMS = ("gravity", "friction", "inertia")
#: The joint-rate filter's cut-off (Hz, device.estimator's) and the rate (rad/s) below which a
#: joint is taken at rest (no Coulomb term, no inertia), as every servo path has them.
CUTOFF, REST = estimator.CUTOFF, estimator.REST


@dataclasses.dataclass(frozen=True)
class Rendered:
    """One force command: ``openhaptics`` (N, OH = frame s: what HD_CURRENT_FORCE gets),
    ``message`` (N, the three numbers of the driver's message), ``compensation`` (N, frame s,
    F_comp before the clamp), ``scale`` (the clamp's factor, 1 where nothing clamped),
    ``singular`` (whether the inverse was damped), ``sigma_min`` (m/rad)."""

    openhaptics: np.ndarray
    message: np.ndarray
    compensation: np.ndarray
    scale: float
    singular: bool
    sigma_min: float


class Frames:
    """The model's every URDF frame at a state, for a force given in one of them: ``rotation(
    frame, theta, gimbal)`` is the frame's rotation in frame s (frame "base_link" included;
    ``prefix`` is the description's). ``base_from_s`` (4, 4): frame s in base_link (REP-103)."""

    def __init__(self, phantom: Phantom) -> None:
        self.prefix = prefix = phantom.description.prefix
        self.gimbal = phantom.config.gimbal
        self.full = phantom.full_coupling  # every joint of the URDF, the gimbal free (the Phantom's)
        self._data = self.full.tree.createData()
        self.names = tuple(f.name for f in self.full.tree.frames if f.name != "universe")
        data = phantom.model.createData()
        pin.framesForwardKinematics(phantom.model, data, pin.neutral(phantom.model))
        self.base_from_s = data.oMf[phantom.model.getFrameId(prefix + "report_s")].homogeneous.copy()
        self._s_from_base = self.base_from_s[:3, :3].T

    def state(self, theta: Vector, gimbal: Vector | None) -> np.ndarray:
        """(theta, g) of the six joints, g at the gimbal's locked_at where None; theta alone without a gimbal."""
        if self.gimbal is None:
            return np.asarray(theta, dtype=float)
        return np.concatenate([theta, self.gimbal.locked_at if gimbal is None else gimbal])

    def configuration(self, theta: Vector, gimbal: Vector | None) -> np.ndarray:
        """Every URDF joint's angle (rad; the mimic joints of the parallelogram included)."""
        return self.full.configuration(self.state(theta, gimbal))

    def rotation(self, frame: str, theta: Vector, gimbal: Vector | None) -> np.ndarray:
        """(3, 3): vectors in ``frame`` to frame s. InvalidInputError naming ``frame_id`` for a
        name the model does not have."""
        if frame == "" or frame == self.prefix + "base_link":
            return self._s_from_base
        if frame not in self.names:
            raise InvalidInputError(f"{frame!r} is not a frame of this model (e.g. {self.prefix}base_link, "
                                    f"{self.prefix}tip{', ' + self.prefix + 'stylus' if self.gimbal else ''})",
                                    argument="frame_id")
        tree = self.full.tree
        pin.framesForwardKinematics(tree, self._data, self.configuration(theta, gimbal))
        return self._s_from_base @ self._data.oMf[tree.getFrameId(frame)].rotation


class Renderer:
    """F for one state: ``__call__(theta, gimbal=None, user=(0, 0, 0), time=None)`` -> Rendered.

    ``phantom``: the device's model (its gravity, its stylus); ``profile``: the driver
    (phantom_pin.interfaces.profiles: its frame and clamp); ``compensate``: a subset of TERMS (gravity,
    friction: the model's friction law, or ``friction`` given, e.g. an identified overlay's
    Phantom.config.actuation.friction); ``max_force`` (N, > 0). theta (rad, the report's) and g
    (rad, OpenHaptics' raw gimbal angles; None: locked_at) of one state; ``user`` (N, frame s);
    ``time`` (s) of the state, needed with friction or inertia (the rate and the acceleration are
    estimated over successive calls: device.estimator.Estimator at CUTOFF); with inertia,
    ``kappa`` (0 < kappa < 1) of M(theta) ddtheta + C(theta, dtheta) dtheta, applied while some
    joint moves faster than REST (as the pyOpenHaptics Compensator). The joint torques are bounded
    by the motors' peak for short forces and their continuous rating on average
    (device.thermal.TorqueBudget, its period the time between states; 1 ms without times).
    """

    def __init__(self, phantom: Phantom, profile: Profile, compensate: Sequence[str] = ("gravity",),
                 max_force: float = math.inf, friction: Friction | None = None, kappa: float = 0.0) -> None:
        _check_options(phantom, compensate, max_force, kappa)
        self.phantom, self.profile = phantom, profile
        self.device = Device(phantom)
        self.gravity, self.friction = "gravity" in compensate, "friction" in compensate
        self.kappa = float(kappa)
        self.law = friction if friction is not None else phantom.config.actuation.friction
        if self.friction and not any(self.law.viscous) and not any(self.law.coulomb):
            raise InvalidInputError(f"the model {phantom.config.name!r} has no friction data (every viscous and "
                                    "Coulomb coefficient 0): give friction= (an identified overlay's)",
                                    argument="compensate")
        self.limit = min(float(max_force), profile.force.clamp)          # N, the norm
        self.estimator = Estimator(cutoff=CUTOFF)
        self.budget = TorqueBudget(self.device)                          # the motors' limits in time

    @property
    def rate(self) -> np.ndarray:
        """The filtered joint rate (rad/s) of the last state."""
        return self.estimator.rate

    def compensation_torque(self, theta: np.ndarray, gimbal: np.ndarray | None, time: float | None) -> np.ndarray:
        """The joint torques (N m) F_comp must produce: gravity, friction and inertia, as asked."""
        tau = np.zeros(3)
        gravity = self.phantom.gravity(theta) if gimbal is None else self.phantom.gravity(theta, gimbal)
        if self.gravity:
            tau += gravity
        if self.friction or self.kappa:
            previous = self.estimator.time
            rate, acceleration = self.estimator.update_at(theta, time)
            if previous is not None and time is not None and time > previous:
                self.budget.period = time - previous
            moving = np.abs(rate) > REST
            if self.friction:
                tau += self.law.torque(np.where(moving, rate, 0.0))
            if self.kappa and moving.any():
                tau += self.kappa * (self.phantom.inverse_dynamics(theta, rate, acceleration, gimbal=gimbal) - gravity)
        return tau

    def __call__(self, theta: object, gimbal: object = None, user: object = (0.0, 0.0, 0.0),
                 time: float | None = None) -> Rendered:
        q = _vector(theta, "theta")
        g = None if gimbal is None else _vector(gimbal, "gimbal")
        f_user = _vector(user, "user")
        jacobian = self.device.tip_jacobian(q)                      # (3, 3), m/rad
        tau = self.compensation_torque(q, g, time)
        u, sigma, vt = np.linalg.svd(jacobian)
        smallest = float(sigma[-1])
        singular = smallest < SINGULAR
        damping = SINGULAR ** 2 * (1 - (smallest / SINGULAR) ** 2) if singular else 0.0
        # J^T F = tau with J = U S V^T: F = U S^-1 V^T tau (damped: S / (S^2 + lambda^2))
        comp = u @ ((sigma / (sigma ** 2 + damping)) * (vt @ tau))
        total = f_user + comp
        scale = 1.0
        norm = float(np.linalg.norm(total))
        if norm > self.limit:
            scale = self.limit / norm
        scale *= self.budget.scale(jacobian.T @ total * scale)
        force = total * scale
        if not np.isfinite(force).all():  # the inputs were finite: only an overflow gets here
            raise InvalidInputError(f"the force is not finite ({force})", argument="user")
        return Rendered(force, self.profile.message_from_openhaptics(force), comp, scale, singular, smallest)


def _check_options(phantom: object, compensate: Sequence[str], max_force: object, kappa: object) -> None:
    """Renderer's options checked: InvalidInputError naming the bad one."""
    if not isinstance(phantom, Phantom):
        raise InvalidInputError(f"expected a phantom_pin.Phantom, got {phantom!r}", argument="phantom")
    unknown = [term for term in compensate if term not in TERMS]
    if unknown or isinstance(compensate, str):
        raise InvalidInputError(f"expected a subset of {', '.join(TERMS)}, got {compensate!r}", argument="compensate")
    if isinstance(max_force, bool) or not isinstance(max_force, (int, float)) or not max_force > 0:
        raise InvalidInputError(f"expected a force > 0 N (inf for none), got {max_force!r}", argument="max_force")
    if isinstance(kappa, bool) or not isinstance(kappa, (int, float)) or not 0 <= kappa < 1 or \
            ("inertia" in compensate) != (kappa > 0):
        raise InvalidInputError(f"expected 0 < kappa < 1 with inertia compensated, 0 without, got {kappa!r}",
                                argument="kappa")


def _vector(value: object, argument: str) -> np.ndarray:
    """``value`` as a finite (3,) float array; InvalidInputError naming ``argument`` otherwise."""
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InvalidInputError(f"expected three finite numbers, got {value!r}", argument=argument) from None
    if array.shape != (3,) or not np.isfinite(array).all() or np.abs(array).max() > 1e6:
        raise InvalidInputError(f"expected three finite numbers of at most 1e6, got {value!r}", argument=argument)
    return array
