"""The builders of a Config: each section of the parameter documents read through the
checked Reader into its typed dataclass, then every link through the one physical check."""

from __future__ import annotations

import dataclasses
import math
import types
from collections.abc import Mapping
from pathlib import Path
from typing import cast

from phantom_pin.config.files import OPTIONAL, PER_JOINT
from phantom_pin.config.reader import TIMESTEP_RANGE, Reader
from phantom_pin.config.types import (
    BODIES,
    GIMBAL_JOINTS,
    GIMBAL_LINKS,
    INTEGRATORS,
    JOINTS,
    POSTURES,
    SATURATIONS,
    Actuation,
    Config,
    CoupledStops,
    Encoder,
    Friction,
    Gimbal,
    Inertial,
    Kinematics,
    Limits,
    Motor,
    MujocoSettings,
    OpenHaptics,
    Scene,
    Stops,
    freeze,
)
from phantom_pin.description.inertial import INERTIA_KEYS, Vector3, carve, problem, tensor6, uncarve, vector3
from phantom_pin.report.parameters import ReportParameters, Unprinted
from phantom_pin.report.parameters import links as report_links

#: The ``sources`` entries each file must have (a non-empty text per section).
SOURCES = {"actuation_file": ("transmission_ratio", "motor", "encoder", "friction"),
           "joint_limits_file": ("stops",), "gimbal_file": ("gimbal",)}


def _kinematics(r: Reader) -> Kinematics:
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


def _openhaptics(r: Reader) -> OpenHaptics | None:
    """actuation.yaml's ``openhaptics`` section (None without one)."""
    arg = "actuation_file"
    if "openhaptics" not in r.documents[arg]:
        return None
    return OpenHaptics(r.text(arg, "openhaptics", "model_type"),
                       r.number(arg, "openhaptics", "nominal_max_force", positive=True),
                       r.number(arg, "openhaptics", "nominal_max_stiffness", positive=True))


def _actuation(r: Reader) -> Actuation:
    return dataclasses.replace(_drive(r), openhaptics=_openhaptics(r))


def _drive(r: Reader) -> Actuation:
    arg = "actuation_file"
    viscous, coulomb = (vector3(r.per_joint(arg, *keys, joints=JOINTS, non_negative=True)) for keys in PER_JOINT[arg])
    friction = Friction(viscous, coulomb)   # PER_JOINT's keys: friction.viscous, friction.coulomb
    saturation = r.text(arg, "saturation")
    if saturation not in SATURATIONS:
        raise r.error(arg, f"saturation must be {' or '.join(SATURATIONS)}, got {saturation!r}")
    public = [r.node(arg, section) is not None for section in DRIVE]
    if public[0] != public[1]:
        raise r.error(arg, "transmission_ratio and motor are either both given or both null (not public)")
    if public[2] and not public[1]:
        raise r.error(arg, "encoder needs the transmission_ratio and the motor (it is read at the motor shaft)")
    if not public[1]:
        effort = vector3(r.number(arg, "joint_torque_limit", j, positive=True) for j in JOINTS)
        velocity = vector3(r.number(arg, "joint_velocity_limit", j, positive=True) for j in JOINTS)
        return Actuation(None, None, None, friction, effort, velocity, effort, saturation)
    return _motor_drive(r, friction, saturation, encoder=public[2])


def _motor_drive(r: Reader, friction: Friction, saturation: str, *, encoder: bool) -> Actuation:
    """_drive's actuation of a model with public motor data (and an encoder if ``encoder``):
    its joint limits follow from the motor and the ratios."""
    arg = "actuation_file"

    def act(*keys: str, **kind: bool) -> float:
        return r.number(arg, *keys, **kind)

    extra = [key for key in JOINT_LIMITS if key in r.documents[arg]]
    if extra:
        raise r.error(arg, f"{extra[0]} is for a model without motor data; with a motor, the joint limits "
                           "follow from max_continuous_torque, max_speed and the ratios")
    motor = Motor(*(act("motor", f.name, positive=True) for f in dataclasses.fields(Motor)))
    problem = motor_problem(motor)
    if problem:
        raise r.error(arg, f"motor: {problem}")
    encoders = None if not encoder else \
        Encoder(*(act("encoder", f.name, positive=True) for f in dataclasses.fields(Encoder)))
    ratios = vector3(act("transmission_ratio", j, positive=True) for j in JOINTS)
    return Actuation(ratios, motor, encoders, friction,
                     vector3(motor.max_continuous_torque * k for k in ratios),
                     vector3(motor.max_speed / k for k in ratios),
                     vector3(motor.stall_torque * k for k in ratios), saturation)


def _limits(r: Reader) -> Limits:
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
    postures = _postures(r, lower, upper)
    return Limits(vector3(lower), vector3(upper),
                  Stops(vector3(s[0] for s in stops), vector3(s[1] for s in stops), coupled,
                                      r.number(arg, "stops", "stiffness", positive=True),
                                      r.number(arg, "stops", "damping", non_negative=True)),
                  types.MappingProxyType(postures))


def _postures(r: Reader, lower: tuple[float, ...], upper: tuple[float, ...]) -> dict[str, Vector3]:
    """The SRDF's named postures (rad), exactly POSTURES, each within the box ``lower`` .. ``upper``."""
    arg = "joint_limits_file"
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
    return postures


def _mujoco(r: Reader) -> MujocoSettings:
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


def _sources(r: Reader) -> dict[str, str]:
    return {section: r.text(arg, "sources", section) for arg, sections in SOURCES.items() for section in sections
            if r.documents[arg] or arg not in OPTIONAL}


#: Largest |coordinate| (m) of the shoulder in OpenHaptics' coordinates: OpenHaptics' origin lies
#: in the device's workspace, within a desk-top arm's reach of its shoulder (the Touch's
#: l1 + l2 = 0.27 m); a number in mm (157 for 0.157) is refused.
OPENHAPTICS_REACH = 1.0


def _gimbal(r: Reader) -> Gimbal | None:
    """The stylus gimbal of gimbal.yaml (None without the file): its joints' ranges, and its three
    links computed from the stated solids (ABS of ``density``), in the URDF link frames
    (parallel to base_link at the zero configuration: a report vector (x, y, z) is (z, x, y)).

    yaw_link, a box of size (a, b, c) along the report's (x, y, z), centred on the gimbal
    centre: m = rho a b c, inertia about the centre m (b^2 + c^2) / 12 about x ... ; pitch_link,
    a cube of side s: m = rho s^3, m s^2 / 6 about every axis; stylus_link, a solid cylinder of
    diameter d and length L on the report's z from z = -tip_offset: m = rho pi d^2 L / 4, its
    centre of mass at z = L / 2 - tip_offset, m d^2 / 8 about its axis, m (3 d^2 / 4 + L^2) / 12
    across."""
    arg = "gimbal_file"
    if not r.documents[arg]:
        return None
    ranges = [r.interval(arg, ("joints",), j) for j in GIMBAL_JOINTS]
    rho = r.number(arg, "density", positive=True)
    a, b, c = r.vector(arg, "yoke", "size", length=3)
    if min(a, b, c) <= 0:
        raise r.error(arg, f"yoke.size must be positive, got {[a, b, c]!r}")
    side = r.number(arg, "pitch_block", "size", positive=True)
    diameter = r.number(arg, "stylus", "diameter", positive=True)
    length = r.number(arg, "stylus", "length", positive=True)
    tip = r.number(arg, "tip_offset", non_negative=True)
    yoke = rho * a * b * c
    block = rho * side**3
    stylus = rho * math.pi * diameter**2 * length / 4
    across = stylus * (3 * diameter**2 / 4 + length**2) / 12
    links = {  # report (x, y, z) -> link frame (z, x, y): xx of the link is zz of the report
        "yaw_link": Inertial(yoke, (0, 0, 0), (yoke * (a * a + b * b) / 12, 0, 0,
                                                yoke * (c * c + b * b) / 12, 0, yoke * (c * c + a * a) / 12)),
        "pitch_link": Inertial(block, (0, 0, 0), (block * side**2 / 6, 0, 0, block * side**2 / 6, 0,
                                                  block * side**2 / 6)),
        "stylus_link": Inertial(stylus, (length / 2 - tip, 0, 0), (stylus * diameter**2 / 8, 0, 0, across, 0, across)),
    }
    assert tuple(links) == GIMBAL_LINKS
    locked = r.vector(arg, "locked_at", length=3)
    for joint, angle, (lo, hi) in zip(GIMBAL_JOINTS, locked, ranges):
        if not lo <= angle <= hi:
            raise r.error(arg, f"locked_at: {joint} at {angle!r} rad is outside its range {lo!r} .. {hi!r}")
    geometry = {key: r.node(arg, key) for key in ("yoke", "pitch_block", "stylus")}
    shoulder = r.vector(arg, "openhaptics_shoulder", length=3)
    if max(abs(v) for v in shoulder) > OPENHAPTICS_REACH:
        raise r.error(arg, f"openhaptics_shoulder: {list(shoulder)!r} m is not within {OPENHAPTICS_REACH:g} m of "
                           "OpenHaptics' origin on every axis (metres, not mm?)")
    return Gimbal(vector3(lo for lo, _ in ranges), vector3(hi for _, hi in ranges),
                  r.number(arg, "velocity_limit", positive=True), tip, vector3(locked),
                  types.MappingProxyType(links), cast(Mapping[str, object], freeze(geometry)), vector3(shoulder))


def _report(r: Reader, kinematics: Kinematics,
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


def _inertial(r: Reader, *keys: str) -> Inertial:
    """A body in full at ``keys`` of physical_parameters.yaml: mass, com, inertia."""
    arg = "physical_parameters_file"
    return Inertial(r.number(arg, *keys, "mass", positive=True), vector3(r.vector(arg, *keys, "com", length=3)),
                    tensor6(r.number(arg, *keys, "inertia", k) for k in INERTIA_KEYS))


def _housing(r: Reader) -> Inertial:
    """The fixed housing under the turret, base_link's inertial (physical_parameters.yaml's
    ``housing``): it moves with nothing, so it enters no joint's dynamics."""
    housing = _inertial(r, "housing")
    trouble = problem(housing)
    if trouble:
        raise r.error("physical_parameters_file", f"housing: {trouble}")
    return housing


def _links(r: Reader, kinematics: Kinematics) -> dict[str, Inertial]:
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
    r = Reader(documents, folder, overridden)
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
            if link in PIN_AT:  # the hinge pin's mass is carved out at the end of the link, a length away
                keys += f", {PIN_AT[link]} (the hinge pin's distance; the inertias do not follow it)"
            raise r.error("physical_parameters_file", f"link {link}: {trouble} (from {keys})")
    return Config(name, folder, overridden, kinematics, r.number("physical_parameters_file", "gravity", positive=True),
                  types.MappingProxyType(links), _housing(r), report, unprinted, actuation, _limits(r), _mujoco(r),
                  cast(Mapping[str, object], freeze(documents["visual_parameters_file"])),
                  types.MappingProxyType(_sources(r)), _gimbal(r))


#: The length at which the hinge pin is carved out of a link (inertial.carve), for error messages.
PIN_AT = {"lower_bar_link": "l1", "crank_link": "l3"}
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
