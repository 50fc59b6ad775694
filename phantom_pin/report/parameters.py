"""The report's numbers and the adapter that turns them into links in full.

The report describes each segment by a few numbers in its own axes (section 3): masses,
diagonal inertias, centres of mass on the segments' axes, inertias of BE and DF about the
shoulder that lump the motors' reflected rotor inertia. ``ReportParameters`` holds them
with the report's appendix symbols (closed_form, derivation and the identification's
lumped constants read them); ``links()`` gives the seven URDF links (phantom_pin.config.
inertial.Inertial: mass, centre of mass, full inertia about it, link frame) that the same
numbers describe, with the rotors moved to the armature and the hinge pins carved out of
their neighbours. This is the only place where the report's structure becomes links.
"""

from __future__ import annotations

import dataclasses

from phantom_pin.description.inertial import Inertial, carve


@dataclasses.dataclass(frozen=True)
class ReportParameters:
    """Numbers of the report, SI units, named as in the report's appendix.

    Lengths l1, l2, l3 (m, eqs 29-31), l5, l6 (m, COM offsets of BE and DF, eqs 63, 73);
    masses m* (kg); inertias I* (kg m^2) in the report's segment axes: A and C about their
    COM, BE and DF about the shoulder, Ibaseyy about axis 1. As in the report, Ibexx, Idfxx
    and Ibaseyy include the motors' reflected rotor inertia. g is gravity (m/s^2), pointing
    along the report's -y.
    """

    l1: float
    l2: float
    l3: float
    l5: float
    l6: float
    g: float
    ma: float
    Iaxx: float
    Iayy: float
    Iazz: float
    mc: float
    Icxx: float
    Icyy: float
    Iczz: float
    mbe: float
    Ibexx: float
    Ibeyy: float
    Ibezz: float
    mdf: float
    Idfxx: float
    Idfyy: float
    Idfzz: float
    Ibaseyy: float


@dataclasses.dataclass(frozen=True)
class Unprinted:
    """What the links need beyond the report: the base's mass and x/z inertias (ESTIMATES,
    kg and kg m^2, report axes) and the hinge pins' mass (kg) and inertia at the pivot
    (kg m^2, base_link axes): physical_parameters.yaml ``segment_g`` and ``hinge_pin``."""

    base_mass: float
    base_inertia_xx: float
    base_inertia_zz: float
    pin_mass: float
    pin_inertia: tuple[float, float, float]


def _about_origin(mass: float, cx: float, cy: float, cz: float, ixx: float, iyy: float,
                  izz: float) -> Inertial:
    """A link from diagonal moments about its frame's origin (base_link axes), moved to the
    centre of mass c by the parallel-axis theorem, I_com = I_origin - mass (|c|^2 1 - c c^T)."""
    return Inertial(mass, (cx, cy, cz), (
        ixx - mass * (cy**2 + cz**2), 0.0 + mass * cx * cy, 0.0 + mass * cx * cz,
        iyy - mass * (cx**2 + cz**2), 0.0 + mass * cy * cz, izz - mass * (cx**2 + cy**2)))


def _at_com(mass: float, com: tuple[float, float, float], ixx: float, iyy: float, izz: float) -> Inertial:
    return Inertial(mass, com, (ixx, 0, 0, iyy, 0, izz))


def links(p: ReportParameters, unprinted: Unprinted, rotor_inertia: float,
          ratios: tuple[float, float, float]) -> dict[str, Inertial]:
    """The seven links of the URDF, by name (no prefix), from the report's numbers.

    A vector (x, y, z) in the report's axes is (z, x, y) in base_link's. The rotor part
    rotor_inertia * ratio_i^2 (kg m^2) leaves I_baseyy, I_bexx and I_dfxx for the armature.
    Each hinge pin (mass and inertia at its pivot) is taken out of its neighbours: its mass
    at the pivot out of crank_link (the crank pin, l3 below the shoulder) and lower_bar_link
    (the forearm pin, at l1 along the bar), its vertical moment out of turret_link, so that
    the 3-DoF dynamics stay the report's exactly: inertial.carve, the one carving (for a model
    in full too), whose numbers are those of the xacro that generated the shipped URDF before
    links were described in full, to the last bit (tests/description/test_build.py).
    """
    l1, l2, l3 = p.l1, p.l2, p.l3
    pin_xx, pin_yy, pin_zz = unprinted.pin_inertia
    bodies = {  # the five bodies as the report gives them, the rotors in the armature
        "turret_link": _at_com(unprinted.base_mass, (0, 0, 0), unprinted.base_inertia_zz,
                               unprinted.base_inertia_xx, p.Ibaseyy - rotor_inertia * ratios[0]**2),
        "upper_arm_link": _about_origin(p.mbe, p.l5, 0, 0, p.Ibezz, p.Ibexx - rotor_inertia * ratios[1]**2,
                                        p.Ibeyy),
        "crank_link": _about_origin(p.mdf, 0, 0, p.l6, p.Idfzz, p.Idfxx - rotor_inertia * ratios[2]**2, p.Idfyy),
        "lower_bar_link": _about_origin(p.mc, l1 / 2, 0, 0, p.Iczz, p.Icxx + p.mc * l1**2 / 4,
                                        p.Icyy + p.mc * l1**2 / 4),
        "forearm_link": _at_com(p.ma, (0, 0, l3 - l2 / 2), p.Iazz, p.Iaxx, p.Iayy),
    }
    return carve(bodies, _at_com(unprinted.pin_mass, (0, 0, 0), pin_xx, pin_yy, pin_zz), p)
