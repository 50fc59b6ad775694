"""The typed, immutable configuration of one device: every number of its parameter files,
checked once, with one name per quantity (SI units, radians); the names of its joints, links
and bodies.

``Config`` is built by phantom_pin.config.read (config.builders) from the YAML files of a folder
(config.files); every consumer (the description, the rigid body, the device, the simulator,
the identification) takes it, through a Description, and reads nothing again.
"""

from __future__ import annotations

import dataclasses
import types
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from phantom_pin.description.inertial import Inertial, vector3
from phantom_pin.exceptions import InvalidInputError
from phantom_pin.report.parameters import ReportParameters, Unprinted

JOINTS = ("joint1", "joint2", "joint3")
#: The links of the URDF that carry mass, in the order of the kinematic tree.
LINKS = ("turret_link", "upper_arm_link", "crank_link", "crank_pin_link", "lower_bar_link",
         "forearm_pin_link", "forearm_link")
#: The mechanism's five rigid bodies (the report's G, BE, DF, C, A): the links but the hinge pins.
BODIES = ("turret_link", "upper_arm_link", "crank_link", "lower_bar_link", "forearm_link")
#: The stylus gimbal's joints, the raw OpenHaptics gimbal angles g1..g3 (yaw, pitch, roll), and
#: the links they carry (config/<model>/gimbal.yaml, where a model's gimbal is public).
GIMBAL_JOINTS = ("joint4", "joint5", "joint6")
GIMBAL_LINKS = ("yaw_link", "pitch_link", "stylus_link")
#: The stop coordinates as linear maps of theta (rows): theta1, theta2, theta3, theta2 - theta3.
STOP_COORDINATES = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, -1.0]])
STOP_COORDINATES.flags.writeable = False
#: Where the simulators clip commanded torques (actuation.yaml's ``saturation``).
SATURATIONS = ("continuous", "peak")
#: MuJoCo's integrators, as config/mjcf.yaml may name them.
INTEGRATORS = ("Euler", "RK4", "implicit", "implicitfast")
#: The SRDF's named postures, which joint_limits.yaml gives (srdf/phantom.srdf.xacro).
POSTURES = ("zero", "resting")


@dataclasses.dataclass(frozen=True)
class Kinematics:
    """l1: shoulder to elbow along the upper arm; l2: elbow to tip along the forearm; l3:
    the parallelogram's crank radius (m; the report's eqs 29-31)."""

    l1: float
    l2: float
    l3: float


@dataclasses.dataclass(frozen=True)
class Motor:
    """At the motor shaft: rotor inertia (kg m^2), max. continuous and stall torque (N m)
    and current (A), torque constant (N m/A), terminal resistance (Ohm), no-load speed (rad/s),
    the winding's thermal time constant (s: how long the stall torque may last before the
    continuous rating binds, device.thermal)."""

    rotor_inertia: float
    max_continuous_torque: float
    max_continuous_current: float
    stall_torque: float
    stall_current: float
    torque_constant: float
    terminal_resistance: float
    max_speed: float
    thermal_time_constant: float


@dataclasses.dataclass(frozen=True)
class Encoder:
    """Optical cycles per motor revolution and counts per cycle (quadrature decoding)."""

    cycles_per_revolution: float
    counts_per_cycle: float


@dataclasses.dataclass(frozen=True)
class Friction:
    """Joint friction, each joint its own law: Coulomb friction with stiction, and viscous.

    ``viscous`` (N m s/rad) and ``coulomb`` (N m): one coefficient per joint, joint1..joint3
    (actuation.yaml gives each as one number, the same on every joint, or as a mapping
    {joint1, joint2, joint3}). In motion, joint i's friction is tau_f,i = viscous[i] * dtheta_i
    + coulomb[i] * sign(dtheta_i), opposing it. At rest a joint sticks: its friction is
    whatever torque holds it, up to its ``coulomb`` (the breakaway torque equals the sliding
    one: no Stribeck effect, which nothing public measured on a PHANToM and MuJoCo's
    frictionloss cannot express). phantom_pin.simulate integrates the stick phase exactly (no
    creep); the URDF's <dynamics damping friction> and the MJCF's damping and frictionloss give
    each joint its own law (MuJoCo's soft constraint creeps slowly: config/mjcf.yaml's friction
    solref)."""

    viscous: tuple[float, float, float]
    coulomb: tuple[float, float, float]

    def __post_init__(self) -> None:
        for name in ("viscous", "coulomb"):     # what the reader checks, for a Friction built in code
            value = getattr(self, name)
            try:
                values = tuple(float(v) for v in value)
            except (TypeError, ValueError):
                values = ()
            if len(values) != 3 or not all(np.isfinite(values)) or min(values) < 0 or \
                    any(isinstance(v, (bool, str)) for v in value):
                raise InvalidInputError(f"expected three finite numbers >= 0, joint1..joint3 "
                                        f"({'N m s/rad' if name == 'viscous' else 'N m'}), got {value!r}",
                                        argument=name)
            object.__setattr__(self, name, values)

    @property
    def uniform(self) -> bool:
        """Whether every joint has the same law (actuation.yaml could say it with one number each)."""
        return len(set(self.viscous)) == 1 and len(set(self.coulomb)) == 1

    def joint(self, index: int) -> tuple[float, float]:
        """(viscous N m s/rad, Coulomb N m) of joint ``index`` (0, 1, 2 for joint1..joint3)."""
        return self.viscous[index], self.coulomb[index]

    def unit_coulomb(self) -> Friction:
        """This law with no viscous term and a unit Coulomb torque on every joint: its ``torque``
        is the direction term, the identification's Coulomb columns."""
        return dataclasses.replace(self, viscous=(0.0, 0.0, 0.0), coulomb=(1.0, 1.0, 1.0))

    def torque(self, dtheta: np.ndarray) -> np.ndarray:
        """The sliding law (N m) at rates dtheta (rad/s, (3,) or (..., 3), joint1..joint3 along the
        last axis): viscous[i] * dtheta_i + coulomb[i] * sign(dtheta_i) per joint; 0 at rest, where
        the torque that holds a joint depends on the load (simulate decides it). The identification's
        friction columns are its two terms. ValueError (InvalidInputError) naming dtheta for
        another shape; one joint's law: ``joint``."""
        rates = np.asarray(dtheta, dtype=float)
        if rates.shape[-1:] != (3,):
            raise InvalidInputError(f"expected rates of shape (3,) or (..., 3) (rad/s), got shape {rates.shape}",
                                    argument="dtheta")
        return np.asarray(self.viscous) * rates + np.asarray(self.coulomb) * np.sign(rates)


@dataclasses.dataclass(frozen=True)
class OpenHaptics:
    """What OpenHaptics reports of the device (actuation.yaml's ``openhaptics``, sourced there):
    ``model_type`` (HD_DEVICE_MODEL_TYPE), ``max_force`` (N, HD_NOMINAL_MAX_FORCE: the force
    norm OpenHaptics clamps HD_CURRENT_FORCE to) and ``max_stiffness`` (N/mm,
    HD_NOMINAL_MAX_STIFFNESS)."""

    model_type: str
    max_force: float
    max_stiffness: float


@dataclasses.dataclass(frozen=True)
class Actuation:
    """Transmission ratios (joint angle = motor angle / ratio), motor, encoder, friction, and
    each joint's torque limit ``effort`` (N m) and speed limit ``velocity`` (rad/s), the URDF's;
    ``openhaptics``: what OpenHaptics reports of the device (None where the file has no section).

    ``ratios``, ``motor`` and ``encoder`` are None where a model's are not public (the Touch):
    actuation.yaml says so with ``null``, and then gives ``joint_torque_limit`` and
    ``joint_velocity_limit`` itself. With a motor, effort = max_continuous_torque * ratio and
    velocity = max_speed / ratio; ``peak`` (N m) is the stall torque at the joint, or the
    configuration's joint_torque_limit.
    """

    ratios: tuple[float, float, float] | None
    motor: Motor | None
    encoder: Encoder | None
    friction: Friction
    effort: tuple[float, float, float]
    velocity: tuple[float, float, float]
    peak: tuple[float, float, float]
    saturation: str = "continuous"
    openhaptics: OpenHaptics | None = None

    def limit(self, policy: str) -> tuple[float, float, float]:
        """Each joint's torque limit (N m) of a saturation ``policy`` (SATURATIONS): "continuous",
        the motors' rating (``effort``), or "peak", their stall torque (``peak``)."""
        return self.effort if policy == "continuous" else self.peak

    @property
    def saturation_torque(self) -> tuple[float, float, float]:
        """Where the simulators clip a commanded joint torque (N m): ``limit`` of ``saturation``
        (the default "continuous"), the same in phantom_pin.simulate and the MJCF's ctrlrange and
        forcerange."""
        return self.limit(self.saturation)

    @property
    def rotor(self) -> tuple[float, tuple[float, float, float]]:
        """(rotor inertia at the motor shaft (kg m^2), transmission ratios): (0, (0, 0, 0))
        without motor data, where the rotors are part of the links' own inertia (the report's
        I_bexx, I_dfxx and I_baseyy include them)."""
        if self.motor is None:
            return 0.0, (0.0, 0.0, 0.0)
        assert self.ratios is not None  # with a motor, its ratios (both given or both not public)
        return self.motor.rotor_inertia, self.ratios

    @property
    def armature(self) -> tuple[float, float, float]:
        """Reflected rotor inertia of each joint, rotor_inertia * ratio^2 (kg m^2); zero
        without motor data (see ``rotor``)."""
        inertia, ratios = self.rotor
        return vector3(inertia * r**2 for r in ratios)


@dataclasses.dataclass(frozen=True)
class CoupledStops:
    """The parallelogram's stops: theta2 - theta3 <= theta2_minus_theta3_max and
    theta3 - theta2 <= theta3_minus_theta2_max (rad), which no URDF box can express."""

    theta2_minus_theta3_max: float
    theta3_minus_theta2_max: float


@dataclasses.dataclass(frozen=True)
class Stops:
    """The real device's mechanical stops: per joint ``lower``/``upper`` (rad), the coupled
    stops, and the hard-stop model tau = K (limit - theta) - B dtheta: ``stiffness`` K
    (N m/rad) and ``damping`` B (N m s/rad)."""

    lower: tuple[float, float, float]
    upper: tuple[float, float, float]
    coupled: CoupledStops
    stiffness: float
    damping: float

    def bounds(self, lower: Sequence[float] | np.ndarray | None = None,
               upper: Sequence[float] | np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """(lower, upper), each (4,) rad, of the stop coordinates (STOP_COORDINATES): the
        joints' stops (or the given per-joint ``lower``/``upper``) and the coupled stops."""
        lo, hi = self.lower if lower is None else lower, self.upper if upper is None else upper
        return (np.array([*lo, -self.coupled.theta3_minus_theta2_max]),
                np.array([*hi, self.coupled.theta2_minus_theta3_max]))

    def force(self, depth: np.ndarray | float, rate: np.ndarray | float,
              engaged: np.ndarray | bool | None = None) -> np.ndarray | float:
        """The hard-stop law: K depth + B rate (N m) of stop coordinates ``depth`` (rad, from
        penetration) beyond their stops at rates ``rate`` (rad/s); the damper acts only while
        the stop is ``engaged``: by default while penetrating (depth != 0; the simulator says
        which stops are engaged over a step). Arrays or floats (the simulator's scalar loop)."""
        return self.stiffness * depth + self.damping * rate * ((depth != 0) if engaged is None else engaged)

    def penetration(self, theta: np.ndarray) -> np.ndarray:
        """Signed depth (rad) of each stop coordinate of postures (..., 3) beyond its stop:
        (..., 4), zero inside. The one stop geometry (Device's stops, the samplers' limits)."""
        c = np.asarray(theta, float) @ STOP_COORDINATES.T
        return c - np.clip(c, *self.bounds())


@dataclasses.dataclass(frozen=True)
class Limits:
    """The URDF's joint box ``lower``..``upper`` (rad, theta1..theta3), the device's stops, and
    the SRDF's named ``postures`` (name -> theta, rad; inside the box)."""

    lower: tuple[float, float, float]
    upper: tuple[float, float, float]
    stops: Stops
    postures: Mapping[str, tuple[float, float, float]]

    def slack(self, theta: np.ndarray) -> np.ndarray:
        """(..., 8) distances (rad) of postures (..., 3) to every limit: the upper, then the
        lower bounds of the stop coordinates (STOP_COORDINATES) over the box intersected with
        the stops' box and the coupled stops: >= 0 inside every limit."""
        c = np.asarray(theta, float) @ STOP_COORDINATES.T
        lower, upper = self.stops.bounds(np.maximum(self.lower, self.stops.lower),
                                         np.minimum(self.upper, self.stops.upper))
        return np.concatenate([upper - c, c - lower], axis=-1)


@dataclasses.dataclass(frozen=True)
class Gimbal:
    """The stylus gimbal (gimbal.yaml): three passive revolute joints (GIMBAL_JOINTS) whose
    axes meet at the arm's tip (eq. 10), their angles OpenHaptics' raw HD_CURRENT_GIMBAL_ANGLES
    g1..g3 (rad): the stylus's rotation in frame s is Ry(theta1) Rx(-theta3) Ry(g1) Rx(-g2)
    Rz(-g3) (report axes: x left, y up, z towards the user). ``lower``/``upper``: the joints'
    ranges (rad); ``velocity``: their URDF speed limit (rad/s); ``tip_offset``: the stylus tip's
    distance from the gimbal centre along the stylus's -z (m); ``locked_at``: the gimbal angles
    (rad) at which the arm's 3-DoF dynamics (Phantom, simulate, Device, the identification) carry
    the gimbal and stylus as a rigid load; ``links``: GIMBAL_LINKS in full (URDF link frames,
    parallel to base_link at the zero configuration; kg, m, kg m^2); ``geometry``: the solids
    those links are computed from and drawn as (read-only YAML data, m); ``openhaptics_shoulder``:
    the shoulder (the joint-1/joint-2 axes' intersection) in OpenHaptics' coordinates (m; an
    ESTIMATE for the Touch), where HD_CURRENT_TRANSFORM's translation puts it
    (phantom_pin.interfaces.conventions.openhaptics_origin)."""

    lower: tuple[float, float, float]
    upper: tuple[float, float, float]
    velocity: float
    tip_offset: float
    locked_at: tuple[float, float, float]
    links: Mapping[str, Inertial]
    geometry: Mapping[str, object]
    openhaptics_shoulder: tuple[float, float, float]


@dataclasses.dataclass(frozen=True)
class Scene:
    """The scene's picture (m): the shoulder above the table top, the stand's radius, the
    table's size (x, y, z) and centre ahead of the shoulder, the floor below the table top."""

    shoulder_height: float
    stand_radius: float
    table_size: tuple[float, float, float]
    table_offset_x: float
    floor_below_table: float


@dataclasses.dataclass(frozen=True)
class MujocoSettings:
    """The MJCF's timestep (s) and integrator, the mimic equalities' solref (time constant
    in timesteps, damping ratio) and solimp (dmin, dmax, width), the joints' dry friction's
    solref (time constant in timesteps, damping ratio), the stops' (joint and tendon limits')
    ``stop_inertia`` (kg m^2: their solref in MuJoCo's direct form is (-K, -B) / stop_inertia,
    K and B the configuration's stops) and solimp, and the scene."""

    timestep: float
    integrator: str
    equality_solref_timesteps: float
    equality_solref_damping_ratio: float
    equality_solimp: tuple[float, float, float]
    friction_solref_timesteps: float
    friction_solref_damping_ratio: float
    stop_inertia: float
    stop_solimp: tuple[float, float, float]
    scene: Scene


def freeze(node: object) -> object:
    """A read-only copy of nested YAML data (mappings become MappingProxyType, lists tuples)."""
    if isinstance(node, dict):
        return types.MappingProxyType({k: freeze(v) for k, v in node.items()})
    if isinstance(node, list):
        return tuple(freeze(v) for v in node)
    return node


def thaw(node: object) -> object:
    """Plain dicts and lists of freeze's output, for writing YAML."""
    if isinstance(node, Mapping):
        return {k: thaw(v) for k, v in node.items()}
    if isinstance(node, tuple):
        return [thaw(v) for v in node]
    return node


@dataclasses.dataclass(frozen=True)
class Config:
    """One device's configuration, read once, immutable.

    ``name``: the model's name (phantom_pin.models()) or the folder's path; ``folder``;
    ``overridden``: whether overrides were applied; ``kinematics`` (m); ``gravity`` (m/s^2,
    along base_link's -z); ``links``: the seven URDF links in full (Inertial by link name,
    without prefix); ``housing``: the fixed housing, base_link's inertial (an ESTIMATE, for
    the tools that drop a root link without one: Gazebo's sdformat); ``report``: the report's
    numbers where the configuration is written
    in the report's terms (else None: closed_form does not apply), and ``unprinted``, what
    its links need beyond them (report.parameters.Unprinted, or None); ``actuation``,
    ``limits`` (box and stops), ``mujoco``, ``visual`` (the primitive geometry, read-only
    YAML data), ``sources`` (section -> where its numbers come from), ``gimbal``: the stylus
    gimbal (Gimbal) where the model has a public one (the Touch), else None.
    """

    name: str
    folder: Path
    overridden: bool
    kinematics: Kinematics
    gravity: float
    links: Mapping[str, Inertial]
    housing: Inertial
    report: ReportParameters | None
    unprinted: Unprinted | None
    actuation: Actuation
    limits: Limits
    mujoco: MujocoSettings
    visual: Mapping[str, object]
    sources: Mapping[str, str]
    gimbal: Gimbal | None = None
