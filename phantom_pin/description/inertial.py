"""A link's mass properties in the URDF's own terms, and the one physical check of a link.

``Inertial``: mass (kg), centre of mass ``com`` (m, 3-vector in the link frame) and the
inertia tensor about the centre of mass in the link frame (kg m^2, six numbers xx, xy,
xz, yy, yz, zz, the tensor's elements: xy = -integral(x y dm), as URDF's ixy).

``problem(inertial)`` is the physical law every consumer of a link relies on: a finite
positive mass, a positive definite inertia, and principal moments a <= b <= c with
a + b - c >= TRIANGLE_SLACK * c. MuJoCo is the strictest consumer: it refuses a body
whose principal moments, as its own eigen-decomposition finds them, break a + b >= c;
with products of inertia, the rounding of that decomposition refuses links up to about
1e-14 c inside the boundary (measured, DEVELOPERS.md). TRIANGLE_SLACK keeps a margin of
100 over that, so every link this check accepts loads in MuJoCo, Pinocchio and Drake
(tests/description/test_inertial.py loads the boundary in MuJoCo).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterable, Mapping
from typing import Protocol

import numpy as np

#: Smallest accepted (a + b - c) / c of a link's principal moments a <= b <= c.
TRIANGLE_SLACK = 1e-12

#: The six numbers of a tensor, in the order of ``Inertial.inertia`` (and of the YAML keys).
INERTIA_KEYS = ("xx", "xy", "xz", "yy", "yz", "zz")
#: Three numbers: a point or vector (m), or one number per joint.
Vector3 = tuple[float, float, float]
#: An inertia tensor's six entries, in INERTIA_KEYS' order (kg m^2).
Tensor6 = tuple[float, float, float, float, float, float]


def vector3(values: Iterable[float]) -> Vector3:
    """Exactly three numbers as a Vector3 (ValueError otherwise); their types are kept."""
    a, b, c = values
    return a, b, c


def tensor6(values: Iterable[float]) -> Tensor6:
    """Exactly six numbers as a Tensor6 (ValueError otherwise); their types are kept."""
    xx, xy, xz, yy, yz, zz = values
    return xx, xy, xz, yy, yz, zz


@dataclasses.dataclass(frozen=True)
class Inertial:
    """Mass (kg), centre of mass (m, link frame) and inertia about it (kg m^2, link frame,
    ``INERTIA_KEYS`` order). The numbers are kept as given: an exact zero written as an
    integer stays one, so that the generated URDF prints it as the xacro did (``0``)."""

    mass: float
    com: tuple[float, float, float]
    inertia: tuple[float, float, float, float, float, float]

    @property
    def tensor(self) -> np.ndarray:
        """The 3x3 inertia tensor about the centre of mass (kg m^2)."""
        xx, xy, xz, yy, yz, zz = (float(v) for v in self.inertia)
        return np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])

    def dynamic_parameters(self) -> np.ndarray:
        """The 10 standard parameters in Pinocchio's order [m, m c, I_origin (xx, xy, yy, xz,
        yz, zz)]: the inertia about the link frame's origin (kg, kg m, kg m^2)."""
        m, c = float(self.mass), np.array(self.com, dtype=float)
        origin = self.tensor + _point(m, c)
        return np.array([m, *(m * c), origin[0, 0], origin[0, 1], origin[1, 1], origin[0, 2],
                         origin[1, 2], origin[2, 2]])

    @classmethod
    def from_dynamic_parameters(cls, pi: np.ndarray) -> Inertial:
        """The inverse of dynamic_parameters (the mass must be positive)."""
        m, hx, hy, hz, ixx, ixy, iyy, ixz, iyz, izz = (float(v) for v in pi)
        c = np.array([hx, hy, hz]) / m
        at_com = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]]) - _point(m, c)
        return cls(m, vector3(float(v) for v in c),
                   tensor6(float(at_com[i, j]) for i, j in ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2))))


def _point(m: float, c: np.ndarray) -> np.ndarray:
    """The inertia of a point mass ``m`` at ``c`` about the origin: m (|c|^2 1 - c c^T). |c|^2 in
    Python floats, not BLAS's dot: OpenBLAS's kernels round it differently (SkylakeX against
    Haswell: a link's iyy written to the URDF 1e-16 apart, and a simulated device's encoder
    counts with it; DEVELOPERS.md)."""
    x, y, z = c.tolist()
    return m * ((x * x + y * y + z * z) * np.eye(3) - np.outer(c, c))


def without_point_mass(body: Inertial, mass: float, point: tuple[float, float, float]) -> Inertial:
    """``body`` less a point mass ``mass`` (kg) at ``point`` (m, link frame): the mass,
    first moment and inertia about the link origin each lose the point's share, and the
    inertia moves back to the new centre of mass (the parallel-axis theorem, both ways)."""
    m, c, p = float(body.mass), np.array(body.com, dtype=float), np.array(point, dtype=float)
    origin = body.tensor + _point(m, c) - _point(mass, p)
    rest = m - mass
    com = (m * c - mass * p) / rest
    at_com = origin - _point(rest, com)
    # a coordinate that neither the body's centre nor the point leaves is the body's, as given
    # (its type too: xacro prints an integer zero as 0, so generated files stay as they were)
    kept = (given if given == 0 and p[k] == 0 else float(com[k]) for k, given in enumerate(body.com))
    return Inertial(rest, vector3(kept),
                    tensor6(float(at_com[i, j]) for i, j in ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2))))


def principal_moments(tensor: np.ndarray) -> np.ndarray:
    """The principal moments a <= b <= c (kg m^2) of a symmetric tensor."""
    return np.linalg.eigvalsh(tensor)


def slack(tensor: np.ndarray) -> float:
    """(a + b - c) / c of the principal moments: the share by which the triangle inequality holds."""
    a, b, c = principal_moments(tensor)
    return float((a + b - c) / c) if c > 0 else -math.inf


def problem(inertial: Inertial) -> str | None:
    """Why a link is not physical (one line, SI units), or None if it is (module doc)."""
    values = [inertial.mass, *inertial.com, *inertial.inertia]
    if not all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in values):
        return "mass, com and inertia must be finite numbers"
    if inertial.mass <= 0:
        return f"mass must be positive (kg), got {inertial.mass!r}"
    moments = principal_moments(inertial.tensor)
    listed = ", ".join(f"{m:.6g}" for m in moments)
    if moments[0] <= 0:
        return f"inertia at the centre of mass is not positive definite (principal moments {listed} kg m^2)"
    if slack(inertial.tensor) < TRIANGLE_SLACK:
        return (f"principal moments of inertia at the centre of mass {listed} kg m^2 break the "
                f"triangle inequality (a + b - c must be at least {TRIANGLE_SLACK:g} c)")
    return None


class Lengths(Protocol):
    """What the carving needs of the arm's lengths (m): l1 (the upper arm) and l3 (the crank)."""

    @property
    def l1(self) -> float: ...

    @property
    def l3(self) -> float: ...


def carve(bodies: Mapping[str, Inertial], pin: Inertial, lengths: Lengths) -> dict[str, Inertial]:
    """The seven links of the URDF (config.types.LINKS) of the mechanism's five rigid bodies
    (config.types.BODIES) and a hinge pin (mass at its pivot, inertia about it; ``lengths``:
    l1 and l3, m): the pin's mass at its pivot out of crank_link (0, 0, -l3) and
    lower_bar_link (l1, 0, 0), the two pins' vertical moment out of turret_link; ``uncarve``
    is its inverse."""
    turret = bodies["turret_link"]
    return {
        "turret_link": Inertial(turret.mass, turret.com, (*turret.inertia[:5], turret.inertia[5] - 2 * pin.inertia[5])),
        "upper_arm_link": bodies["upper_arm_link"],
        "crank_link": without_point_mass(bodies["crank_link"], pin.mass, (0.0, 0.0, -lengths.l3)),
        "crank_pin_link": pin,
        "lower_bar_link": without_point_mass(bodies["lower_bar_link"], pin.mass, (lengths.l1, 0.0, 0.0)),
        "forearm_pin_link": pin,
        "forearm_link": bodies["forearm_link"],
    }


def uncarve(links: Mapping[str, Inertial], lengths: Lengths) -> dict[str, Inertial]:
    """The five bodies (BODIES) of seven links: ``carve`` undone (a point mass taken out with a
    negative mass is put back), for a model in the report's form as for one in full."""
    pin = links["crank_pin_link"]
    turret = links["turret_link"]
    return {
        "turret_link": Inertial(turret.mass, turret.com, (*turret.inertia[:5], turret.inertia[5] + 2 * pin.inertia[5])),
        "upper_arm_link": links["upper_arm_link"],
        "crank_link": without_point_mass(links["crank_link"], -pin.mass, (0.0, 0.0, -lengths.l3)),
        "lower_bar_link": without_point_mass(links["lower_bar_link"], -pin.mass, (lengths.l1, 0.0, 0.0)),
        "forearm_link": links["forearm_link"],
    }
