"""The typed, immutable configuration of one device: every number of its parameter files,
checked once, with one name per quantity (SI units, radians).

``Config`` is built by phantom_pin.config.read from the YAML files of a folder (files.py);
every consumer (the description, the rigid body, the device, the simulator, the
identification) takes it, through a Description, and reads nothing again.
"""

from __future__ import annotations

import dataclasses
import math
import types
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import cast

import numpy as np

from phantom_pin.config.files import FILES, is_number
from phantom_pin.exceptions import ParameterFileError
from phantom_pin.inertial import INERTIA_KEYS, Inertial, Vector3, problem, tensor6, vector3, without_point_mass
from phantom_pin.report.parameters import ReportParameters, Unprinted
from phantom_pin.report.parameters import links as report_links

JOINTS = ("joint1", "joint2", "joint3")
#: The links of the URDF that carry mass, in the order of the kinematic tree.
LINKS = ("turret_link", "upper_arm_link", "crank_link", "crank_pin_link", "lower_bar_link",
         "forearm_pin_link", "forearm_link")
#: The mechanism's five rigid bodies (the report's G, BE, DF, C, A): the links but the hinge pins.
BODIES = ("turret_link", "upper_arm_link", "crank_link", "lower_bar_link", "forearm_link")
#: Largest |joint limit| (rad): a revolute joint's range beyond one turn each way repeats
#: postures and describes no stop of this arm (mahilab's widest stop is 3.74 rad).
JOINT_LIMIT_BOUND = 2 * math.pi
#: Largest magnitude of any number of a configuration (SI units): the largest shipped is 1750
#: (kg/m^3); past it squares and products of inertia overflow (l1 = 1e308: OverflowError) and
#: MuJoCo's first step goes NaN. A scale, not a physical limit: a desk-top arm is far inside it.
MAX_MAGNITUDE = 1e6
#: The MJCF's timestep (s): a haptic loop's 1e-6 to 1e-2 s (MuJoCo went NaN on its first step
#: of 1 s with the shipped stops and friction solref).
TIMESTEP_RANGE = (1e-6, 1e-2)
#: The stop coordinates as linear maps of theta (rows): theta1, theta2, theta3, theta2 - theta3.
STOP_COORDINATES = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, -1.0]])
STOP_COORDINATES.flags.writeable = False
#: Where the simulators clip commanded torques (actuation.yaml's ``saturation``).
SATURATIONS = ("continuous", "peak")
#: MuJoCo's integrators, as config/mjcf.yaml may name them.
INTEGRATORS = ("Euler", "RK4", "implicit", "implicitfast")
#: The SRDF's named postures, which joint_limits.yaml gives (srdf/phantom_1_5.srdf.xacro).
POSTURES = ("zero", "resting")
#: The ``sources`` entries each file must have (a non-empty text per section).
SOURCES = {"actuation_file": ("transmission_ratio", "motor", "encoder", "friction"),
           "joint_limits_file": ("stops",)}


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
    and current (A), torque constant (N m/A), terminal resistance (Ohm), no-load speed (rad/s)."""

    rotor_inertia: float
    max_continuous_torque: float
    max_continuous_current: float
    stall_torque: float
    stall_current: float
    torque_constant: float
    terminal_resistance: float
    max_speed: float


@dataclasses.dataclass(frozen=True)
class Encoder:
    """Optical cycles per motor revolution and counts per cycle (quadrature decoding)."""

    cycles_per_revolution: float
    counts_per_cycle: float


@dataclasses.dataclass(frozen=True)
class Friction:
    """Joint friction, the same on each joint: Coulomb friction with stiction, and viscous.

    In motion, tau_f = viscous * dtheta + coulomb * sign(dtheta) (N m s/rad, N m), opposing
    it. At rest a joint sticks: its friction is whatever torque holds it, up to ``coulomb``
    (the breakaway torque equals the sliding one: no Stribeck effect, which nothing public
    measured on a PHANToM and MuJoCo's frictionloss cannot express). phantom_pin.simulate
    integrates the stick phase exactly (no creep); the MJCF gives MuJoCo's frictionloss the
    same level (its soft constraint creeps slowly: config/mjcf.yaml's friction solref)."""

    viscous: float
    coulomb: float

    def torque(self, dtheta: np.ndarray | float) -> np.ndarray | float:
        """The sliding law viscous * dtheta + coulomb * sign(dtheta) (N m) at rates dtheta (rad/s,
        an array or one float); 0 at rest, where the torque that holds a joint depends on the
        load (simulate decides it). The identification's friction columns are its two terms."""
        if isinstance(dtheta, float):
            return self.viscous * dtheta + (math.copysign(self.coulomb, dtheta) if dtheta else 0.0)
        return self.viscous * dtheta + self.coulomb * np.sign(dtheta)


@dataclasses.dataclass(frozen=True)
class Actuation:
    """Transmission ratios (joint angle = motor angle / ratio), motor, encoder, friction, and
    each joint's torque limit ``effort`` (N m) and speed limit ``velocity`` (rad/s), the URDF's.

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
class Scene:
    """scene.xml's picture (m): the shoulder above the table top, the stand's radius, the
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


def _freeze(node: object) -> object:
    """A read-only copy of nested YAML data (mappings become MappingProxyType, lists tuples)."""
    if isinstance(node, dict):
        return types.MappingProxyType({k: _freeze(v) for k, v in node.items()})
    if isinstance(node, list):
        return tuple(_freeze(v) for v in node)
    return node


def thaw(node: object) -> object:
    """Plain dicts and lists of _freeze's output, for writing YAML."""
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
    YAML data), ``sources`` (section -> where its numbers come from).
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


class _Reader:
    """Typed, checked access to the documents; every error names the file and the key."""

    def __init__(self, documents: dict[str, dict], folder: Path, overridden: bool) -> None:
        self.documents, self.folder, self.overridden = documents, folder, overridden

    def error(self, arg: str, message: str) -> ParameterFileError:
        prefix = "after the overrides, " if self.overridden else ""
        return ParameterFileError(f"{prefix}{self.folder / FILES[arg]}: {message}")

    def node(self, arg: str, *keys: str) -> object:
        node: object = self.documents[arg]
        for depth, key in enumerate(keys):
            if not isinstance(node, dict) or key not in node:
                raise self.error(arg, f"missing key {'.'.join(keys[:depth + 1])}")
            node = node[key]
        return node

    def number(self, arg: str, *keys: str, positive: bool = False, non_negative: bool = False) -> float:
        node = self.node(arg, *keys)
        name = ".".join(keys)
        if not is_number(node):
            raise self.error(arg, f"{name} must be a finite number, got {node!r}")
        value = cast(float, node)  # an int or a float (is_number)
        if not math.isfinite(value):
            raise self.error(arg, f"{name} must be a finite number, got {value!r}")
        if abs(value) > MAX_MAGNITUDE:
            raise self.error(arg, f"{name} must be at most {MAX_MAGNITUDE:g} in magnitude (SI units), got {value!r}")
        if positive and value <= 0:
            raise self.error(arg, f"{name} must be positive, got {value!r}")
        if non_negative and value < 0:
            raise self.error(arg, f"{name} must not be negative, got {value!r}")
        return value

    def vector(self, arg: str, *keys: str, length: int) -> tuple:
        value = self.node(arg, *keys)
        if not (isinstance(value, list) and len(value) == length
                and all(is_number(v) and math.isfinite(v) and abs(v) <= MAX_MAGNITUDE for v in value)):
            raise self.error(arg, f"{'.'.join(keys)} must be a list of {length} finite numbers of magnitude at most "
                                  f"{MAX_MAGNITUDE:g}, got {value!r}")
        return tuple(value)

    def text(self, arg: str, *keys: str) -> str:
        value = self.node(arg, *keys)
        if not isinstance(value, str) or not value.strip():
            raise self.error(arg, f"{'.'.join(keys)} must be a non-empty text, got {value!r}")
        return value

    def interval(self, arg: str, prefix: tuple[str, ...], joint: str) -> tuple[float, float]:
        lo = self.number(arg, *prefix, joint, "lower")
        hi = self.number(arg, *prefix, joint, "upper")
        name = ".".join((*prefix, joint))
        for side, value in (("lower", lo), ("upper", hi)):
            if abs(value) > JOINT_LIMIT_BOUND:
                raise self.error(arg, f"{name}.{side} must be within one turn (|limit| <= 2 pi rad), got {value!r}")
        if lo >= hi:
            raise self.error(arg, f"{name}.lower must be below {name}.upper")
        return lo, hi


def _kinematics(r: _Reader) -> Kinematics:
    return Kinematics(*(r.number("kinematics_file", k, positive=True) for k in ("l1", "l2", "l3")))


#: The sections of actuation.yaml that a model may declare not public (``null``).
DRIVE = ("transmission_ratio", "motor", "encoder")
#: The joint limits actuation.yaml gives itself when the motor is not public.
JOINT_LIMITS = ("joint_torque_limit", "joint_velocity_limit")


#: Largest relative disagreement between a motor's torque and its torque constant times the
#: current at the same point of its data sheet (maxon RE 25: 1.5 % at the nominal point, where
#: the no-load current is not torque; 0.2 % at stall).
MOTOR_TOLERANCE = 0.1


def motor_problem(motor: Motor) -> str:
    """What makes a motor's data sheet numbers inconsistent with each other ("" if nothing):
    the continuous torque and current must be below the stall torque and current, and each
    torque (N m) the torque constant (N m/A) times its current (A) within MOTOR_TOLERANCE."""
    if motor.max_continuous_torque >= motor.stall_torque:
        return (f"max_continuous_torque {motor.max_continuous_torque:g} N m must be below stall_torque "
                f"{motor.stall_torque:g} N m")
    if motor.max_continuous_current >= motor.stall_current:
        return (f"max_continuous_current {motor.max_continuous_current:g} A must be below stall_current "
                f"{motor.stall_current:g} A")
    for torque, current in (("max_continuous_torque", "max_continuous_current"), ("stall_torque", "stall_current")):
        expected = motor.torque_constant * getattr(motor, current)
        if abs(getattr(motor, torque) / expected - 1) > MOTOR_TOLERANCE:
            return (f"{torque} {getattr(motor, torque):g} N m is not torque_constant x {current} "
                    f"({motor.torque_constant:g} N m/A x {getattr(motor, current):g} A = {expected:.4g} N m) within "
                    f"{MOTOR_TOLERANCE:.0%}")
    return ""


def _actuation(r: _Reader) -> Actuation:
    arg = "actuation_file"

    def act(*keys: str, **kind: bool) -> float:
        return r.number(arg, *keys, **kind)

    friction = Friction(act("friction", "viscous", non_negative=True), act("friction", "coulomb", non_negative=True))
    saturation = r.text(arg, "saturation")
    if saturation not in SATURATIONS:
        raise r.error(arg, f"saturation must be {' or '.join(SATURATIONS)}, got {saturation!r}")
    public = [r.node(arg, section) is not None for section in DRIVE]
    document = r.documents[arg]
    if public[0] != public[1]:
        raise r.error(arg, "transmission_ratio and motor are either both given or both null (not public)")
    if public[2] and not public[1]:
        raise r.error(arg, "encoder needs the transmission_ratio and the motor (it is read at the motor shaft)")
    if not public[1]:
        effort = vector3(act("joint_torque_limit", j, positive=True) for j in JOINTS)
        velocity = vector3(act("joint_velocity_limit", j, positive=True) for j in JOINTS)
        return Actuation(None, None, None, friction, effort, velocity, effort, saturation)
    extra = [key for key in JOINT_LIMITS if key in document]
    if extra:
        raise r.error(arg, f"{extra[0]} is for a model without motor data; with a motor, the joint limits "
                           "follow from max_continuous_torque, max_speed and the ratios")
    motor = Motor(*(act("motor", f.name, positive=True) for f in dataclasses.fields(Motor)))
    problem = motor_problem(motor)
    if problem:
        raise r.error(arg, f"motor: {problem}")
    encoder = None if not public[2] else \
        Encoder(*(act("encoder", f.name, positive=True) for f in dataclasses.fields(Encoder)))
    ratios = vector3(act("transmission_ratio", j, positive=True) for j in JOINTS)
    return Actuation(ratios, motor, encoder, friction,
                     vector3(motor.max_continuous_torque * k for k in ratios),
                     vector3(motor.max_speed / k for k in ratios),
                     vector3(motor.stall_torque * k for k in ratios), saturation)


def _limits(r: _Reader) -> Limits:
    arg = "joint_limits_file"
    box = [r.interval(arg, (), j) for j in JOINTS]
    stops = [r.interval(arg, ("stops",), j) for j in JOINTS]
    lower, upper = tuple(b[0] for b in box), tuple(b[1] for b in box)
    coupled = CoupledStops(r.number(arg, "stops", "theta2_minus_theta3_max"),
                           r.number(arg, "stops", "theta3_minus_theta2_max"))
    forward, backward = coupled.theta2_minus_theta3_max, coupled.theta3_minus_theta2_max
    if forward + backward <= 0:
        raise r.error(arg, f"stops.theta2_minus_theta3_max + stops.theta3_minus_theta2_max must be "
                           f"positive (an open interval), got {forward!r} + {backward!r}")
    for name, (lo, hi) in (("box", (lower, upper)), ("stops", ([s[0] for s in stops], [s[1] for s in stops]))):
        low, high = lo[1] - hi[2], hi[1] - lo[2]
        if forward <= low or -backward >= high:
            raise r.error(arg, f"the coupled stops {-backward:.4f} <= theta2 - theta3 <= {forward:.4f} rad "
                               f"leave no posture in the {name}, where theta2 - theta3 spans "
                               f"{low:.4f} .. {high:.4f} rad")
    listed = r.node(arg, "postures")
    if not isinstance(listed, dict) or set(listed) != set(POSTURES):
        raise r.error(arg, f"postures must give exactly {' and '.join(POSTURES)} (the SRDF's named postures, "
                           f"[theta1, theta2, theta3] rad), got {listed!r}")
    postures = {}
    for name in POSTURES:
        theta = r.vector(arg, "postures", name, length=3)
        if not all(lo <= t <= hi for t, lo, hi in zip(theta, lower, upper)):
            raise r.error(arg, f"postures.{name} {list(theta)} rad is outside the box joint1..joint3")
        postures[name] = theta
    return Limits(vector3(lower), vector3(upper),
                  Stops(vector3(s[0] for s in stops), vector3(s[1] for s in stops), coupled,
                                      r.number(arg, "stops", "stiffness", positive=True),
                                      r.number(arg, "stops", "damping", non_negative=True)),
                  types.MappingProxyType(postures))


def _mujoco(r: _Reader) -> MujocoSettings:
    arg = "mjcf_file"
    integrator = r.node(arg, "integrator")
    if integrator not in INTEGRATORS:
        raise r.error(arg, f"integrator must be {', '.join(INTEGRATORS[:-1])} or {INTEGRATORS[-1]}, got {integrator!r}")
    scene = Scene(r.number(arg, "scene", "shoulder_height", positive=True),
                  r.number(arg, "scene", "stand_radius", positive=True),
                  r.vector(arg, "scene", "table_size", length=3),
                  r.number(arg, "scene", "table_offset_x"),
                  r.number(arg, "scene", "floor_below_table", positive=True))
    timestep = r.number(arg, "timestep", positive=True)
    if not TIMESTEP_RANGE[0] <= timestep <= TIMESTEP_RANGE[1]:
        raise r.error(arg, f"timestep must be {TIMESTEP_RANGE[0]:g} to {TIMESTEP_RANGE[1]:g} s, got {timestep!r}")
    return MujocoSettings(timestep, integrator,
                          r.number(arg, "equality_solref_timesteps", positive=True),
                          r.number(arg, "equality_solref_damping_ratio", positive=True),
                          r.vector(arg, "equality_solimp", length=3),
                          r.number(arg, "friction_solref_timesteps", positive=True),
                          r.number(arg, "friction_solref_damping_ratio", positive=True),
                          r.number(arg, "stop_inertia", positive=True), r.vector(arg, "stop_solimp", length=3), scene)


def _sources(r: _Reader) -> dict[str, str]:
    return {section: r.text(arg, "sources", section) for arg, sections in SOURCES.items() for section in sections}


def _report(r: _Reader, kinematics: Kinematics,
            actuation: Actuation) -> tuple[ReportParameters, Unprinted, dict[str, Inertial]]:
    """The report's numbers of physical_parameters.yaml (the report's form) and their links."""
    arg = "physical_parameters_file"

    def phys(*keys: str, positive: bool = True) -> float:
        return r.number(arg, *keys, positive=positive)

    def inertia(segment: str) -> Vector3:
        return vector3(phys(segment, "inertia", axis) for axis in ("xx", "yy", "zz"))

    report = ReportParameters(
        kinematics.l1, kinematics.l2, kinematics.l3, phys("segment_be", "com", positive=False),
        phys("segment_df", "com", positive=False), phys("gravity"),
        phys("segment_a", "mass"), *inertia("segment_a"), phys("segment_c", "mass"), *inertia("segment_c"),
        phys("segment_be", "mass"), *inertia("segment_be"), phys("segment_df", "mass"), *inertia("segment_df"),
        phys("segment_g", "inertia_yy"))
    unprinted = Unprinted(phys("segment_g", "mass"), phys("segment_g", "inertia_xx"), phys("segment_g", "inertia_zz"),
                          phys("hinge_pin", "mass"),
                          vector3(phys("hinge_pin", "inertia", a) for a in ("xx", "yy", "zz")))
    return report, unprinted, report_links(report, unprinted, *actuation.rotor)


def _inertial(r: _Reader, *keys: str) -> Inertial:
    """A body in full at ``keys`` of physical_parameters.yaml: mass, com, inertia."""
    arg = "physical_parameters_file"
    return Inertial(r.number(arg, *keys, "mass", positive=True), vector3(r.vector(arg, *keys, "com", length=3)),
                    tensor6(r.number(arg, *keys, "inertia", k) for k in INERTIA_KEYS))


def _housing(r: _Reader) -> Inertial:
    """The fixed housing under the turret, base_link's inertial (physical_parameters.yaml's
    ``housing``): it moves with nothing, so it enters no joint's dynamics."""
    housing = _inertial(r, "housing")
    trouble = problem(housing)
    if trouble:
        raise r.error("physical_parameters_file", f"housing: {trouble}")
    return housing


def _links(r: _Reader, kinematics: Kinematics) -> dict[str, Inertial]:
    """The seven links of physical_parameters.yaml in the URDF's form: the five bodies in
    full (``links``) with the hinge pins (``hinge_pin``) carved out of their neighbours,
    as the report's adapter does (report.parameters.links): each pin's mass at its pivot
    out of crank_link (0, 0, -l3) and lower_bar_link (l1, 0, 0), its vertical moment out of
    turret_link, so that the 3-DoF dynamics stay those of the five bodies exactly."""
    arg = "physical_parameters_file"
    listed = r.node(arg, "links")
    if not isinstance(listed, dict) or set(listed) != set(BODIES):
        raise r.error(arg, f"links must name exactly the bodies {', '.join(BODIES)}, got "
                           f"{sorted(listed) if isinstance(listed, dict) else listed!r}")
    bodies = {name: _inertial(r, "links", name) for name in BODIES}
    for name, body in bodies.items():  # before the carving, so that the error names the body's own keys
        trouble = problem(body)
        if trouble:
            raise r.error(arg, f"link {name}: {trouble} (from links.{name})")
    pin_mass = r.number(arg, "hinge_pin", "mass", positive=True)
    xx, yy, zz = (r.number(arg, "hinge_pin", "inertia", k, positive=True) for k in ("xx", "yy", "zz"))
    return carve(bodies, Inertial(pin_mass, (0, 0, 0), (xx, 0, 0, yy, 0, zz)), kinematics)


def carve(bodies: Mapping[str, Inertial], pin: Inertial, kinematics: Kinematics) -> dict[str, Inertial]:
    """The seven links (LINKS) of the five bodies (BODIES) and a hinge pin (mass at its pivot,
    inertia about it): the pin's mass at its pivot out of crank_link (0, 0, -l3) and
    lower_bar_link (l1, 0, 0), the two pins' vertical moment out of turret_link; ``uncarve``
    is its inverse."""
    turret = bodies["turret_link"]
    return {
        "turret_link": Inertial(turret.mass, turret.com, (*turret.inertia[:5], turret.inertia[5] - 2 * pin.inertia[5])),
        "upper_arm_link": bodies["upper_arm_link"],
        "crank_link": without_point_mass(bodies["crank_link"], pin.mass, (0.0, 0.0, -kinematics.l3)),
        "crank_pin_link": pin,
        "lower_bar_link": without_point_mass(bodies["lower_bar_link"], pin.mass, (kinematics.l1, 0.0, 0.0)),
        "forearm_pin_link": pin,
        "forearm_link": bodies["forearm_link"],
    }


def uncarve(links: Mapping[str, Inertial], kinematics: Kinematics) -> dict[str, Inertial]:
    """The five bodies (BODIES) of seven links: ``carve`` undone (a point mass taken out with a
    negative mass is put back), for a model in the report's form as for one in full."""
    pin = links["crank_pin_link"]
    turret = links["turret_link"]
    return {
        "turret_link": Inertial(turret.mass, turret.com, (*turret.inertia[:5], turret.inertia[5] + 2 * pin.inertia[5])),
        "upper_arm_link": links["upper_arm_link"],
        "crank_link": without_point_mass(links["crank_link"], -pin.mass, (0.0, 0.0, -kinematics.l3)),
        "lower_bar_link": without_point_mass(links["lower_bar_link"], -pin.mass, (kinematics.l1, 0.0, 0.0)),
        "forearm_link": links["forearm_link"],
    }


#: The report form's keys of physical_parameters.yaml that the links in full replace.
REPORT_SEGMENTS = ("segment_a", "segment_c", "segment_be", "segment_df", "segment_g", "density")


def in_full(documents: dict[str, dict], config: Config) -> dict[str, dict]:
    """``documents`` (of ``config``) with physical_parameters.yaml in the links' full form: a
    model in the report's form gets its five bodies (``uncarve`` of its links, the rotors
    staying in the armature) in place of the report's segments; its dynamics are unchanged.
    The form that an overlay of ``links.*`` keys (phantom-pin identify's) applies to."""
    physical = dict(documents["physical_parameters_file"])
    if "links" in physical:
        return documents
    for key in REPORT_SEGMENTS:
        physical.pop(key, None)
    physical["links"] = {name: {"mass": body.mass, "com": list(body.com),
                                "inertia": dict(zip(INERTIA_KEYS, body.inertia))}
                         for name, body in uncarve(config.links, config.kinematics).items()}
    return {**documents, "physical_parameters_file": physical}


def build(documents: dict[str, dict], name: str, folder: Path, overridden: bool) -> Config:
    """The Config of the parameter files' ``documents`` (files.FILES keys); ParameterFileError
    naming the file and the key of the first missing, malformed or non-physical number."""
    r = _Reader(documents, folder, overridden)
    kinematics, actuation = _kinematics(r), _actuation(r)
    physical = documents["physical_parameters_file"]
    report_form = "segment_a" in physical
    if report_form == ("links" in physical):
        raise r.error("physical_parameters_file", "needs either the report's segments (segment_a ...) or "
                                                  "the links in full (links), not both or neither")
    if report_form:
        report, unprinted, links = _report(r, kinematics, actuation)
    else:
        report, unprinted, links = None, None, _links(r, kinematics)
    for link, inertial in links.items():
        trouble = problem(inertial)
        if trouble:
            keys = f"links.{link}, hinge_pin" if report is None else REPORT_KEYS[link]
            raise r.error("physical_parameters_file", f"link {link}: {trouble} (from {keys})")
    return Config(name, folder, overridden, kinematics, r.number("physical_parameters_file", "gravity", positive=True),
                  types.MappingProxyType(links), _housing(r), report, unprinted, actuation, _limits(r), _mujoco(r),
                  cast(Mapping[str, object], _freeze(documents["visual_parameters_file"])),
                  types.MappingProxyType(_sources(r)))


#: The keys of the report's form that feed each link, for error messages.
REPORT_KEYS = {
    "turret_link": "segment_g.mass, segment_g.inertia_*, actuation.motor.rotor_inertia, "
                   "transmission_ratio.joint1, hinge_pin.inertia.zz",
    "upper_arm_link": "segment_be.mass, segment_be.com, segment_be.inertia, "
                      "actuation.motor.rotor_inertia, transmission_ratio.joint2",
    "crank_link": "segment_df.mass, segment_df.com, segment_df.inertia, "
                  "actuation.motor.rotor_inertia, transmission_ratio.joint3, hinge_pin.mass",
    "crank_pin_link": "hinge_pin.mass, hinge_pin.inertia",
    "lower_bar_link": "segment_c.mass, segment_c.inertia, hinge_pin.mass",
    "forearm_pin_link": "hinge_pin.mass, hinge_pin.inertia",
    "forearm_link": "segment_a.mass, segment_a.inertia",
}

