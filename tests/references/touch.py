"""Independent reference for the model touch's ESTIMATED mass properties: the stated geometric
approximation of config/touch/physical_parameters.yaml (aluminium tubes, discs and a bar),
integrated here with SymPy over each shape placed in the report's segment axes (x along joint
axes 2/3, y up, z forward at the zero configuration), not with the textbook formulas the YAML's
comments quote. Nothing is read from the project's YAML or code; the shapes are transcribed from
that file's comments:

    segment A (forearm): tube OD 10 mm, ID 8 mm, length l2, along y; about its centre of mass
    segment C (lower bar): tube OD 6 mm, ID 4 mm, length l1, along z; about its centre of mass
    segment BE: tube OD 12 mm, ID 10 mm, from the shoulder to z = l1, plus a drum (disc of
        radius 35 mm, 3 mm thick, axis x, centred on the shoulder); about the shoulder
    segment DF: the same drum, plus a bar 8 mm (x) by 3 mm (z) from the shoulder down to
        y = -l3; about the shoulder
    segment G (turret): a solid cylinder of radius 30 mm, height 40 mm, on axis 1 (y), centred

with l1 = l2 = 0.13335 m (Ubitrack), l3 = 0.020 m, density 2700 kg/m^3.

    REFERENCE: {segment: {"mass": kg, "com": m or None, "inertia": {xx, yy, zz} kg m^2}}
"""

from __future__ import annotations

import functools

import sympy as sp

RHO = sp.Rational(2700)
L1 = L2 = sp.Rational(13335, 100000)
L3 = sp.Rational(20, 1000)
MM = sp.Rational(1, 1000)
r, phi, s, u, v = sp.symbols("r phi s u v", real=True)


def _integrate(density_volume, bounds, position):
    """(mass, first moment (3,), second moments about the origin {xx, yy, zz}) of a body whose
    points are ``position`` (x, y, z) in terms of the integration variables, with volume
    element ``density_volume`` (density x Jacobian)."""
    x, y, z = position

    def integral(f):
        result = f * density_volume
        for bound in bounds:
            result = sp.integrate(result, bound)
        return sp.nsimplify(result)

    mass = integral(1)
    first = [integral(c) for c in (x, y, z)]
    second = {"xx": integral(y**2 + z**2), "yy": integral(x**2 + z**2), "zz": integral(x**2 + y**2)}
    return mass, first, second


def _cylinder(outer, inner, start, end, axis):
    """A tube (or solid, inner = 0) of radii outer/inner along ``axis`` from start to end (m)."""
    c, d = r * sp.cos(phi), r * sp.sin(phi)
    position = {"x": (s, c, d), "y": (c, s, d), "z": (c, d, s)}[axis]
    return _integrate(RHO * r, [(r, inner, outer), (phi, 0, 2 * sp.pi), (s, start, end)], position)


def _box(a, b, start, end):
    """A bar of cross-section a (x) by b (z), from y = start to y = end."""
    return _integrate(RHO, [(u, -a / 2, a / 2), (v, -b / 2, b / 2), (s, start, end)], (u, s, v))


def _sum(*bodies):
    mass = sum(b[0] for b in bodies)
    first = [sum(b[1][k] for b in bodies) for k in range(3)]
    second = {k: sum(b[2][k] for b in bodies) for k in ("xx", "yy", "zz")}
    return mass, first, second


def _about_com(body):
    """Second moments about the centre of mass (parallel axis theorem, exactly)."""
    mass, first, second = body
    c = [f / mass for f in first]
    return {"xx": second["xx"] - mass * (c[1]**2 + c[2]**2), "yy": second["yy"] - mass * (c[0]**2 + c[2]**2),
            "zz": second["zz"] - mass * (c[0]**2 + c[1]**2)}


def _reference() -> dict[str, dict]:
    forearm = _cylinder(5 * MM, 4 * MM, 0, L2, "y")
    bar = _cylinder(3 * MM, 2 * MM, 0, L1, "z")
    drum = _cylinder(35 * MM, 0, -sp.Rational(3, 2) * MM, sp.Rational(3, 2) * MM, "x")
    be = _sum(_cylinder(6 * MM, 5 * MM, 0, L1, "z"), drum)
    df = _sum(drum, _box(8 * MM, 3 * MM, -L3, 0))
    turret = _cylinder(30 * MM, 0, -20 * MM, 20 * MM, "y")
    return {
        "segment_a": {"mass": forearm[0], "com": None, "inertia": _about_com(forearm)},
        "segment_c": {"mass": bar[0], "com": None, "inertia": _about_com(bar)},
        "segment_be": {"mass": be[0], "com": be[1][2] / be[0], "inertia": be[2]},       # com along z
        "segment_df": {"mass": df[0], "com": df[1][1] / df[0], "inertia": df[2]},       # com along y
        "segment_g": {"mass": turret[0], "com": None, "inertia": turret[2]},
    }


@functools.cache
def reference() -> dict[str, dict]:
    """The segments' mass properties as floats (computed on first use: SymPy takes a second,
    which every pytest worker paid at collection when this was a module constant)."""
    return {segment: {key: (None if value is None else
                            {k: float(x) for k, x in value.items()} if isinstance(value, dict) else float(value))
                      for key, value in entry.items()}
            for segment, entry in _reference().items()}


if __name__ == "__main__":
    for segment, entry in reference().items():
        print(segment, entry)


# -- the stylus gimbal (config/touch/gimbal.yaml) ---------------------------------------------
# Its solids, transcribed from that file's comments, ABS of 1050 kg/m^3, in the report's axes
# at g = 0 (x: the pitch axis, y: the yaw axis, z: the stylus, towards the user), about the
# gimbal centre:
#     yaw_link: a box 60 (x) by 17 (y) by 12 (z) mm, centred
#     pitch_link: a cube of 17.4 mm, centred
#     stylus_link: a solid cylinder of diameter 11.8 mm on z, from z = -39 mm (the tip) to +91 mm
#
#     GIMBAL_REFERENCE: {link: {"mass": kg, "first": [3] kg m, "second": {xx, yy, zz} kg m^2}}
# (second moments about the gimbal centre; the products vanish by symmetry).

ABS = sp.Rational(1050, 2700)  # the integrators' density is aluminium's; everything scales with it


def _gimbal() -> dict[str, tuple]:
    side = sp.Rational(174, 10) * MM
    bodies = {"yaw_link": _box(60 * MM, 12 * MM, -sp.Rational(17, 2) * MM, sp.Rational(17, 2) * MM),
              "pitch_link": _box(side, side, -side / 2, side / 2),
              "stylus_link": _cylinder(sp.Rational(59, 10) * MM, 0, -39 * MM, 91 * MM, "z")}
    return {name: (mass * ABS, [f * ABS for f in first], {k: v * ABS for k, v in second.items()})
            for name, (mass, first, second) in bodies.items()}


@functools.cache
def gimbal_reference() -> dict[str, dict]:
    """GIMBAL_REFERENCE as floats, computed on first use (as reference())."""
    return {name: {"mass": float(mass), "first": [float(f) for f in first],
                   "second": {k: float(v) for k, v in second.items()}}
            for name, (mass, first, second) in _gimbal().items()}


def __getattr__(name: str) -> dict:
    """REFERENCE and GIMBAL_REFERENCE, computed when first read."""
    if name == "REFERENCE":
        return reference()
    if name == "GIMBAL_REFERENCE":
        return gimbal_reference()
    raise AttributeError(name)
