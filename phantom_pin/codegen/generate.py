"""A self-contained C99 header of one configuration's dynamics and kinematics, generated
symbolically from its URDF (the same links, frames and <mimic> coupling Pinocchio loads).

The generator runs the recursive Newton-Euler algorithm once over the URDF's tree with SymPy
symbols for theta (rad), dtheta (rad/s) and ddtheta (rad/s^2) and the configuration's numbers
as constants; each mimic joint's angle is multiplier * theta_primary + offset, so its torque
returns to the primary joint times the multiplier (tau = G^T tau_tree). Gravity is the pass
at zero rates, the mass matrix the passes at unit accelerations without gravity (plus the
rotors' armature on the diagonal), the Coriolis vector the pass at zero accelerations without
gravity. The tip's position in the report's frame s is the product of the joint transforms,
its Jacobian the exact derivative; a model with a stylus gimbal also gets the stylus frame's
pose in frame s, the product of the transforms with the gimbal's joints free (the dynamics
hold them at locked_at). SymPy's common-subexpression elimination and C printer
write each function as straight-line double arithmetic (literals with 17 significant digits).
"""

from __future__ import annotations

import math
import textwrap
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

from phantom_pin.codegen.c import ASSUMES as _ASSUMES
from phantom_pin.codegen.c import body as _body
from phantom_pin.codegen.c import function as _function
from phantom_pin.codegen.servo import openhaptics
from phantom_pin.codegen.tree import ARM_JOINTS as ARM_JOINTS  # (where it lived before)
from phantom_pin.codegen.tree import Joint, read_tree
from phantom_pin.config import MODELS
from phantom_pin.config.types import GIMBAL_JOINTS
from phantom_pin.description.build import Description, describe, description_of
from phantom_pin.description.gimbal import locked
from phantom_pin.description.urdf import parse
from phantom_pin.exceptions import InvalidInputError, PhantomPinError

try:
    import sympy as sp
    from sympy.printing.c import C99CodePrinter
except ImportError:  # pragma: no cover - the codegen extra
    sp = None
    C99CodePrinter = object

#: The URDF links of the report's frame s, of the tip (the gimbal's centre) and of the stylus
#: frame (a model with a stylus gimbal; Phantom.stylus_pose's).
FRAME_S, TIP, STYLUS = "report_s", "tip", "stylus"


def committed_header(name: str) -> Path:
    """The committed header of a shipped model: include/ROBOT.h in the ROS package, beside
    urdf/ROBOT.urdf (a ROS package's public headers live in include/)."""
    model = MODELS[name]
    return model.urdf.parent.parent / "include" / f"{model.urdf.stem}.h"


def _require_sympy() -> None:
    """PhantomPinError in one line without SymPy (the command line prints it, exit 2)."""
    if sp is None:
        raise PhantomPinError("phantom_pin.codegen needs the package sympy: pip install 'phantom_pin[codegen]'")


def is_identifier(name: object) -> bool:
    """Whether ``name`` is a C identifier (letters, digits, underscores; not a leading digit)."""
    return (isinstance(name, str) and name.isascii() and name.replace("_", "a").isalnum()
            and not name[0].isdigit())


# -- symbolic algebra -----------------------------------------------------------------------
def _num(value: float) -> Any:
    """A configuration number as a SymPy constant: exact 0 and +-1, else 17 digits."""
    if value in (0.0, 1.0, -1.0):
        return sp.Integer(int(value))
    return sp.Float(value, 17)


def _rpy(rpy: tuple[float, float, float], exact: bool = False) -> Any:
    """URDF's fixed-axis roll-pitch-yaw rotation Rz(y) Ry(p) Rx(r), numeric; ``exact``: entries
    within 1e-15 of 0 or +-1 (the URDF's 1.5707963267948966 is pi/2 to 6e-17) taken as
    exactly that, so that they drop out of the products instead of adding terms of 6e-17."""
    r, p, y = rpy
    cr, sr, cp, sp_, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    rows = ((cy * cp, cy * sp_ * sr - sy * cr, cy * sp_ * cr + sy * sr),
            (sy * cp, sy * sp_ * sr + cy * cr, sy * sp_ * cr - cy * sr),
            (-sp_, cp * sr, cp * cr))
    def snapped(v: float) -> float:
        return float(round(v)) if exact and abs(v - round(v)) < 1e-15 else v
    return sp.Matrix([[_num(snapped(v)) for v in row] for row in rows])


def _rotation(axis: tuple[float, float, float], angle: Any) -> Any:
    """Rotation by ``angle`` about a unit ``axis`` (Rodrigues)."""
    c, s = sp.cos(angle), sp.sin(angle)
    a = sp.Matrix([_num(v) for v in axis])
    cross = sp.Matrix([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return c * sp.eye(3) + s * cross + (1 - c) * (a * a.T)


def _cross(a: Any, b: Any) -> Any:
    return sp.Matrix([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


class _Model:
    """The URDF's tree with its constants as SymPy matrices, for the symbolic passes; a stylus
    gimbal held at locked_at, as Phantom holds it, or, ``free``, its joints coordinates 3..5
    (for the stylus's pose only: rnea covers the arm's three). ``exact``: the joints' fixed
    rotations by multiples of pi/2 exact (_rpy's)."""

    def __init__(self, description: Description, free: bool = False, exact: bool = False) -> None:
        gimbal = description.config.gimbal
        urdf = description.urdf if gimbal is None or free else \
            locked(description.urdf, description.prefix, gimbal.locked_at)
        self.root, self.joints, links = read_tree(urdf, description.prefix,
                                                   ARM_JOINTS + GIMBAL_JOINTS if free else ARM_JOINTS)
        self.gravity = _num(description.config.gravity)
        self.armature = [_num(a) for a in description.config.actuation.armature]
        self.links = {}
        for name, link in links.items():
            ixx, ixy, ixz, iyy, iyz, izz = link.inertia
            rotation = _rpy(link.rpy)
            inertia = sp.Matrix([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]]).applyfunc(_num)
            self.links[name] = (_num(link.mass), sp.Matrix([_num(v) for v in link.com]),
                                rotation * inertia * rotation.T)
        self.placements = {j.name: (_rpy(j.rpy, exact), sp.Matrix([_num(v) for v in j.xyz])) for j in self.joints}

    @staticmethod
    def angle(joint: Joint, theta: list[Any]) -> Any:
        """A joint's angle (rad): multiplier * its coordinate + offset (0 for a fixed joint)."""
        if joint.coordinate is None:
            return sp.Integer(0)
        return _num(joint.multiplier) * theta[joint.coordinate] + _num(joint.offset)

    def rotation(self, joint: Joint, theta: list[Any]) -> Any:
        """The child frame's orientation in the parent's (parent -> child rotation)."""
        fixed = self.placements[joint.name][0]
        if joint.axis is None:
            return fixed
        return fixed * _rotation(joint.axis, self.angle(joint, theta))

    def rnea(self, theta: list[Any], dtheta: list[Any], ddtheta: list[Any], gravity: bool) -> list[Any]:
        """Joint torques (N m) on theta of the tree with every mimic joint following its
        primary: Newton-Euler in each link's own frame; no armature. One torque per coordinate
        (a free gimbal's three after the arm's)."""
        zero = sp.zeros(3, 1)
        state = {self.root: (zero, zero, sp.Matrix([0, 0, self.gravity]) if gravity else zero)}
        rotations = {}
        for joint in self.joints:  # outwards: angular velocity, its rate, origin acceleration
            w, dw, a = state[joint.parent]
            r = self.rotation(joint, theta)
            rotations[joint.name] = r
            t = self.placements[joint.name][1]
            rt = r.T
            w_in = rt * w
            a_child = rt * (a + _cross(dw, t) + _cross(w, _cross(w, t)))
            if joint.axis is None:
                state[joint.child] = (w_in, rt * dw, a_child)
                continue
            assert joint.coordinate is not None
            axis = sp.Matrix([_num(v) for v in joint.axis])
            k = _num(joint.multiplier)
            rate, acc = k * dtheta[joint.coordinate], k * ddtheta[joint.coordinate]
            state[joint.child] = (w_in + axis * rate, rt * dw + axis * acc + _cross(w_in, axis * rate), a_child)
        wrench = {}
        for link, (w, dw, a) in state.items():  # each link's own force and moment about its origin
            if link not in self.links:
                wrench[link] = (zero, zero)
                continue
            m, c, inertia = self.links[link]
            force = m * (a + _cross(dw, c) + _cross(w, _cross(w, c)))
            wrench[link] = (force, inertia * dw + _cross(w, inertia * w) + _cross(c, force))
        tau = [sp.Integer(0)] * len(theta)
        for joint in reversed(self.joints):  # inwards: accumulate on the parent, project on the axis
            f, n = wrench[joint.child]
            if joint.axis is not None:
                assert joint.coordinate is not None
                axis = [_num(v) for v in joint.axis]
                torque = axis[0] * n[0] + axis[1] * n[1] + axis[2] * n[2]
                tau[joint.coordinate] += _num(joint.multiplier) * torque
            r, t = rotations[joint.name], self.placements[joint.name][1]
            rf = r * f
            pf, pn = wrench[joint.parent]
            wrench[joint.parent] = (pf + rf, pn + r * n + _cross(t, rf))
        return tau

    def pose(self, link: str, theta: list[Any]) -> tuple[Any, Any]:
        """(rotation, origin) of ``link`` in the root link's frame."""
        by_child = {j.child: j for j in self.joints}
        rotation, origin = sp.eye(3), sp.zeros(3, 1)
        while link != self.root:
            joint = by_child[link]
            # parent <- child: x_parent = R x_child + t
            r, t = self.rotation(joint, theta), self.placements[joint.name][1]
            rotation, origin = r * rotation, r * origin + t
            link = joint.parent
        return rotation, origin

    def merged_pose(self, link: str, theta: list[Any]) -> tuple[Any, Any]:
        """pose(link, theta) with the rotations of consecutive joints about one axis (and no
        fixed rotation between them) merged into one rotation by the sum of their angles: the
        parallelogram's mimic joints then cancel (-theta3 + theta2 - theta2 + theta3) instead
        of leaving sums of sin^2 and cos^2. The same transform in far fewer operations (the
        committed headers' tip position keeps pose()'s product, whose text they are)."""
        by_child = {j.child: j for j in self.joints}
        chain = []
        while link != self.root:
            chain.append(by_child[link])
            link = chain[-1].parent
        fixed, axis, angle, origin = sp.eye(3), None, sp.Integer(0), sp.zeros(3, 1)
        for joint in reversed(chain):  # root outwards: x_root = R x_child + origin
            placement, t = self.placements[joint.name]
            rotation = fixed if axis is None else fixed * _rotation(axis, angle)
            origin = origin + rotation * t
            if placement == sp.eye(3) and joint.axis in (None, axis):  # one more turn about axis
                angle = angle + self.angle(joint, theta)
            else:
                fixed, axis, angle = rotation * placement, joint.axis, self.angle(joint, theta)
        return (fixed if axis is None else fixed * _rotation(axis, angle)), origin


def _leaner(exprs: list[Any]) -> list[Any]:
    """``exprs`` or, if it takes fewer operations after common-subexpression elimination,
    their expansion with sin(theta_i)^2 = 1 - cos(theta_i)^2: the Newton-Euler passes rotate
    vectors into each link and back, which leaves sums such as g cos^2 + g sin^2 (the
    expansion halves gravity's and the mass matrix's operations, not the Coriolis vector's)."""
    def is_power(e: Any) -> bool:
        return bool(e.is_Pow and e.base.func == sp.sin and e.exp.is_Integer and e.exp >= 2)

    def reduced(e: Any) -> Any:  # sin^n = sin^(n mod 2) (1 - cos^2)^(n div 2)
        return sp.sin(e.base.args[0]) ** (e.exp % 2) * (1 - sp.cos(e.base.args[0]) ** 2) ** (e.exp // 2)
    expanded = [sp.expand(sp.expand(e).replace(is_power, reduced)) for e in exprs]

    def cost(candidate: list[Any]) -> int:
        temps, reduced = sp.cse(candidate, order="none")
        return int(sum(sp.count_ops(e) for _, e in temps) + sum(sp.count_ops(e) for e in reduced))
    return expanded if cost(expanded) < cost(exprs) else exprs


def header(model: str | Path | Description, prefix: str = "phantom",
           overrides: Mapping[str, object] | None = None,
           progress: Callable[[float], None] | None = None, *, argument: str = "model") -> str:
    """The C99 header of a model name (phantom_pin.models()) or a configuration folder with
    ``overrides`` (as describe()'s), its functions named ``prefix``_...; its banner names
    the model, the configuration's model and the overrides. describe()'s errors as they are;
    InvalidInputError naming ``prefix`` unless it is a C identifier. A Description is taken
    as it is (its banner then says so: the overrides it was built with are not known).
    ``progress``: called with the share done (0..1), for a progress bar; generation takes
    seconds (SymPy). ``argument``: the name that errors about ``model`` give it."""
    _require_sympy()
    if not is_identifier(prefix):
        raise InvalidInputError(f"must be a C identifier (letters, digits, _), got {prefix!r}",
                                argument="prefix")
    overlay = dict(overrides or {})
    if isinstance(model, Description):
        description, origin = model, f"a Description of {model.config.name}"
        overlay_text = "as built into that Description"
    else:
        description = describe(model, overrides=overlay) if overlay else description_of(model, argument)
        origin = (f"robots/phantom_description/config/{model}" if description.model is not None
                  and str(model) == description.config.name else str(model))
        overlay_text = "; ".join(f"{k} = {v!r}" for k, v in sorted(overlay.items())) or "none"
    return _header(description, prefix, origin, overlay_text, progress or (lambda share: None))


def _wrapped(text: str) -> str:
    """``text`` in comment lines of at most 100 characters (an overlay's keys: one line each
    would be thousands of characters)."""
    return "\n *   ".join(textwrap.wrap(text, 88, break_long_words=False, break_on_hyphens=False)) or text


#: The functions' bodies by the model's numbers (its URDF, actuation and gimbal): SymPy takes
#: seconds per model, and the prefix, origin and overlay text only name and describe them.
_BODIES: dict[tuple[str, str, str], dict[str, str]] = {}


def _bodies(description: Description, progress: Callable[[float], None]) -> dict[str, str]:
    """Each function's C body (by function name), generated once per model's numbers."""
    key = (description.urdf, repr(description.config.actuation), repr(description.config.gimbal))
    if key not in _BODIES:
        _BODIES[key] = _generate(description, progress)
    return _BODIES[key]


def _generate(description: Description, progress: Callable[[float], None]) -> dict[str, str]:
    """The bodies of the dynamics and kinematics functions (SymPy: rnea, cse, C printing)."""
    model = _Model(description)
    theta = list(sp.symbols("q0:3", real=True))
    dtheta = list(sp.symbols("dq0:3", real=True))
    ddtheta = list(sp.symbols("ddq0:3", real=True))
    f = list(sp.symbols("f0:3", real=True))
    zero = [sp.Integer(0)] * 3
    arm = model.armature
    gravity = _leaner(model.rnea(theta, zero, zero, True))
    progress(0.1)
    mass = _mass(model, theta)
    progress(0.25)
    coriolis = _leaner(model.rnea(theta, dtheta, zero, False))
    progress(0.45)
    full = model.rnea(theta, dtheta, ddtheta, True)
    inverse = _leaner([full[i] + arm[i] * ddtheta[i] for i in range(3)])
    progress(0.75)
    r_s, p_s = model.pose(FRAME_S, theta)
    _, p_tip = model.pose(TIP, theta)
    position = r_s.T * (p_tip - p_s)
    jacobian = [[sp.diff(position[i], theta[j]) for j in range(3)] for i in range(3)]
    T, D, A = ("theta", theta), ("dtheta", dtheta), ("ddtheta", ddtheta)
    bodies = {
        "gravity": _body([(f"tau[{i}]", gravity[i]) for i in range(3)], [T]),
        "inverse_dynamics": _body([(f"tau[{i}]", inverse[i]) for i in range(3)], [T, D, A]),
        "mass_matrix": _body([(f"M[{3 * i + j}]", mass[i][j]) for i in range(3) for j in range(3)], [T]),
        "coriolis": _body([(f"c[{i}]", coriolis[i]) for i in range(3)], [T, D]),
        "tip_position": _body([(f"p[{i}]", position[i]) for i in range(3)], [T]),
        "tip_jacobian": _body([(f"J[{3 * i + j}]", jacobian[i][j]) for i in range(3) for j in range(3)], [T]),
        "jacobian_transpose_force": _body([(f"tau[{j}]", sum(jacobian[i][j] * f[i] for i in range(3)))
                                           for j in range(3)], [T, ("f", f)]),
    }
    bodies["friction"] = _friction_body(description)
    if description.config.gimbal is not None:
        bodies["stylus_pose"] = _stylus_body(description)
        bodies["gravity_stylus"] = _gravity_stylus_body(description)
    return bodies


def _mass(model: _Model, theta: list) -> list[list[Any]]:
    """M(theta) as 3 x 3 expressions, the armature on its diagonal: a column per unit
    acceleration of Newton-Euler without gravity, its upper triangle made lean once."""
    zero = [sp.Integer(0)] * 3
    arm = model.armature
    columns = [model.rnea(theta, zero, [sp.Integer(int(i == j)) for i in range(3)], False) for j in range(3)]
    upper = _leaner([columns[j][i] + (arm[i] if i == j else 0) for i in range(3) for j in range(i, 3)])
    index = {(i, j): k for k, (i, j) in enumerate((i, j) for i in range(3) for j in range(i, 3))}
    return [[upper[index[min(i, j), max(i, j)]] for j in range(3)] for i in range(3)]


def _gravity_stylus_body(description: Description) -> str:
    """The arm's gravity torques with the stylus gimbal held at given angles (Phantom.gravity's
    ``gimbal=``): the Newton-Euler gravity pass over the URDF with the gimbal's joints free, at
    zero rates, the arm's three torques (the gimbal's own are the hand's)."""
    model = _Model(description, free=True)
    theta = list(sp.symbols("q0:3", real=True))
    gimbal = list(sp.symbols("g0:3", real=True))
    zero = [sp.Integer(0)] * 6
    gravity = _leaner(model.rnea(theta + gimbal, zero, zero, True)[:3])
    return _body([(f"tau[{i}]", gravity[i]) for i in range(3)], [("theta", theta), ("gimbal", gimbal)])


def _friction_body(description: Description) -> str:
    """The friction law in motion (config.Friction, Device.friction): viscous dtheta + Coulomb
    sign(dtheta) per joint, sign(0) = 0."""
    law = description.config.actuation.friction
    lines = []
    for i in range(3):
        lines.append(f"    tau[{i}] = {law.viscous[i]!r} * dtheta[{i}] + {law.coulomb[i]!r} * "
                     f"((dtheta[{i}] > 0.0) - (dtheta[{i}] < 0.0));")
    return "\n".join(lines)


def _header(description: Description, prefix: str, origin: str, overlay: str,
            progress: Callable[[float], None]) -> str:
    body = _bodies(description, progress)
    guard = f"{prefix.upper()}_MODEL_H"
    units = ("theta: the report's joint angles theta1..theta3 (rad); dtheta (rad/s); ddtheta (rad/s^2);\n"
             "torques in N m on theta. " + _ASSUMES)
    parts = [
        _banner(description, prefix, origin, overlay) +
        f"#ifndef {guard}\n#define {guard}\n\n#include <math.h>\n\n"
        f"/* 1 where the model has a stylus gimbal (HD_CURRENT_GIMBAL_ANGLES), else 0. */\n"
        f"#define {prefix.upper()}_STYLUS {int(description.config.gimbal is not None)}\n\n"
        f"#ifdef __cplusplus\nextern \"C\" {{\n#endif\n",
        _function(f"Gravity torques tau = N(theta) (N m) at rest.\n{units}",
                  f"{prefix}_gravity(const double theta[3], double tau[3])", body["gravity"]),
        _function(f"Inverse dynamics tau = M(theta) ddtheta + C(theta, dtheta) dtheta + N(theta) (N m),\n"
                  f"the rotors' armature included; no friction.\n{units}",
                  f"{prefix}_inverse_dynamics(const double theta[3], const double dtheta[3], "
                  f"const double ddtheta[3], double tau[3])", body["inverse_dynamics"]),
        _function(f"Joint-space mass matrix M(theta) (kg m^2), row-major M[3*i + j], symmetric,\n"
                  f"the rotors' armature on its diagonal.\n{units}",
                  f"{prefix}_mass_matrix(const double theta[3], double M[9])", body["mass_matrix"]),
        _function(f"Coriolis and centrifugal torques c = C(theta, dtheta) dtheta (N m).\n{units}",
                  f"{prefix}_coriolis(const double theta[3], const double dtheta[3], double c[3])", body["coriolis"]),
        _function(f"Tip position p (m) in the report's frame s (x left, y up, z forward); the tip is\n"
                  f"the gimbal's centre.\n{_ASSUMES}",
                  f"{prefix}_tip_position(const double theta[3], double p[3])", body["tip_position"]),
        _function(f"Tip Jacobian J = dp/dtheta (m/rad), row-major J[3*i + j]: the tip's linear velocity\n"
                  f"in frame s is J dtheta.\n{_ASSUMES}",
                  f"{prefix}_tip_jacobian(const double theta[3], double J[9])", body["tip_jacobian"]),
        _function(f"Joint torques tau = J^T f (N m) that exert the force f (N, frame s) at the tip.\n{_ASSUMES}",
                  f"{prefix}_jacobian_transpose_force(const double theta[3], const double f[3], double tau[3])",
                  body["jacobian_transpose_force"]),
        *([] if "stylus_pose" not in body else [_stylus(prefix, body["stylus_pose"])]),
        openhaptics(prefix, body, description.config.gimbal is not None),
        f"#ifdef __cplusplus\n}}\n#endif\n\n#endif /* {guard} */\n",
    ]
    return "\n".join(parts)


def _banner(description: Description, prefix: str, origin: str, overlay: str) -> str:
    """The header's opening comment: the model, the configuration's source, the overlay, the
    gravity and armature, and what the header covers."""
    name, gimbal = description.config.name, description.config.gimbal
    if gimbal is None:
        covers = (" * parallelogram's mimic joints following them); the tip is the gimbal's centre. A\n"
                  " * stylus gimbal, where the device has one, is not part of this header.\n")
    else:
        covers = (" * parallelogram's mimic joints following them); the tip is the gimbal's centre. The\n"
                  " * dynamics carry the stylus gimbal held at its locked_at angles "
                  f"({', '.join(repr(a) for a in gimbal.locked_at)} rad);\n"
                  f" * {prefix}_stylus_pose takes its angles (OpenHaptics' raw gimbal angles).\n")
    return (f"/* {prefix}: the dynamics and kinematics of the PHANToM model {name}, generated by\n"
            f" * phantom-pin codegen (phantom_pin.codegen) from its configuration. Do not edit: regenerate.\n"
            f" *\n"
            f" * Model: {name} (URDF robot {parse(description.urdf).get('name')})\n"
            f" * Configuration: {origin}\n"
            f" * Overlay: {_wrapped(overlay)}\n"
            f" * Gravity: {description.config.gravity!r} m/s^2 along base_link's -z; armature (kg m^2): "
            f"{', '.join(repr(a) for a in description.config.actuation.armature)}\n"
            f" *\n"
            f" * The arm's three joints (the report's theta1..theta3, the URDF's joint1..joint3, the\n"
            f"{covers}"
            f" * C99 and C++, double precision, only <math.h>: static inline functions, no allocation,\n"
            f" * no global state, every function re-entrant. Arrays are row-major. Every function\n"
            f" * assumes finite input and does not check it.\n"
            f" */\n")


def _stylus_body(description: Description) -> str:
    """The stylus frame's pose in frame s (Phantom.stylus_pose): the product of the joint
    transforms with the gimbal's joints free, frame s's inverse first; the URDF's quarter turns
    exact (a change of 6e-17 against Pinocchio's, which leaves the result's rounding)."""
    model = _Model(description, free=True, exact=True)
    theta = list(sp.symbols("q0:3", real=True))
    gimbal = list(sp.symbols("g0:3", real=True))
    r_s, p_s = model.merged_pose(FRAME_S, theta + gimbal)
    r_stylus, p_stylus = model.merged_pose(STYLUS, theta + gimbal)
    position, rotation = r_s.T * (p_stylus - p_s), r_s.T * r_stylus
    pose = _leaner([*position, *(rotation[i, j] for i in range(3) for j in range(3))])
    outputs = [(f"p[{i}]", pose[i]) for i in range(3)] + [(f"R[{k}]", pose[3 + k]) for k in range(9)]
    return _body(outputs, [("theta", theta), ("gimbal", gimbal)])


def _stylus(prefix: str, body: str) -> str:
    """The stylus pose's function (_stylus_body) named ``prefix``_stylus_pose."""
    return _function(
        "Pose of the stylus frame in the report's frame s (x left, y up, z forward), as\n"
        "phantom_pin.Phantom.stylus_pose: its origin p (m) is the gimbal's centre (the tip); its\n"
        "rotation R, row-major R[3*i + j], has the stylus frame's x, y, z axes in frame s as its\n"
        "columns, +z along the stylus towards its back end. theta: the report's theta1..theta3\n"
        "(rad); gimbal: OpenHaptics' raw gimbal angles g1..g3 (rad, the URDF's joint4..joint6).\n"
        f"{_ASSUMES}",
        f"{prefix}_stylus_pose(const double theta[3], const double gimbal[3], double p[3], double R[9])", body)
