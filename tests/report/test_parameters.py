"""report.parameters: the report's adapter (links) against the links derived by hand in the test
from the report's numbers (base_link's (x, y, z) is the report's (z, x, y); the parallel-axis
theorem moves BE's and DF's moments about the shoulder to their centres of mass), the rotors'
share J r^2 moved out to the armature, and the hinge pins carved out conserving the mass and
the first moments (1e-15)."""

import dataclasses

import numpy as np
import pytest

from helpers import CONFIG
from phantom_pin.report.parameters import ReportParameters, Unprinted, links

P = CONFIG.report
NO_PIN = dataclasses.replace(CONFIG.unprinted, pin_mass=0.0, pin_inertia=(0.0, 0.0, 0.0))
RATIOS = CONFIG.actuation.rotor[1]


def _diagonal(link):
    ixx, ixy, ixz, iyy, iyz, izz = link.inertia
    assert (ixy, ixz, iyz) == (0, 0, 0)
    return ixx, iyy, izz


def test_the_links_are_the_reports_bodies_in_base_links_axes():
    """Without pins and rotors: the turret (the base's mass at its axis; Ibaseyy about the
    vertical), BE and DF with their centres l5 along x and l6 along z and their moments about
    the shoulder less m l^2 off their own axis, the lower bar C centred at l1/2 with its own
    moments, the forearm A at l3 - l2/2 below the elbow's axis along z; masses exact."""
    got = links(P, NO_PIN, 0.0, RATIOS)
    assert sorted(got) == sorted(["turret_link", "upper_arm_link", "crank_link", "crank_pin_link", "lower_bar_link",
                                  "forearm_pin_link", "forearm_link"])
    u = NO_PIN
    expected = {
        "turret_link": (u.base_mass, (0, 0, 0), (u.base_inertia_zz, u.base_inertia_xx, P.Ibaseyy)),
        "upper_arm_link": (P.mbe, (P.l5, 0, 0), (P.Ibezz, P.Ibexx - P.mbe * P.l5**2, P.Ibeyy - P.mbe * P.l5**2)),
        "crank_link": (P.mdf, (0, 0, P.l6), (P.Idfzz - P.mdf * P.l6**2, P.Idfxx - P.mdf * P.l6**2, P.Idfyy)),
        "lower_bar_link": (P.mc, (P.l1 / 2, 0, 0), (P.Iczz, P.Icxx, P.Icyy)),
        "forearm_link": (P.ma, (0, 0, P.l3 - P.l2 / 2), (P.Iazz, P.Iaxx, P.Iayy)),
    }
    for name, (mass, com, inertia) in expected.items():
        link = got[name]
        assert link.mass == mass and link.com == pytest.approx(com, abs=1e-17), name
        np.testing.assert_allclose(_diagonal(link), inertia, rtol=1e-14, atol=1e-19, err_msg=name)
    assert got["crank_pin_link"].mass == 0 and got["forearm_pin_link"].mass == 0


def test_the_rotors_move_to_the_armature():
    """J r_i^2 leaves the turret's vertical moment (r_1), BE's and DF's moment about the
    shoulder axis (r_2, r_3), and nothing else (1e-18 kg m^2)."""
    j, ratios = 1e-6, (13.0, 11.0, 9.0)            # three ratios apart (the shipped r_2 = r_3)
    with_rotors, without = links(P, NO_PIN, j, ratios), links(P, NO_PIN, 0.0, ratios)
    moved = {name: np.subtract(without[name].inertia, with_rotors[name].inertia) for name in without}
    expected = dict.fromkeys(without, np.zeros(6))
    expected["turret_link"] = np.array([0, 0, 0, 0, 0, j * ratios[0] ** 2])
    expected["upper_arm_link"] = np.array([0, 0, 0, j * ratios[1] ** 2, 0, 0])
    expected["crank_link"] = np.array([0, 0, 0, j * ratios[2] ** 2, 0, 0])
    for name in without:
        np.testing.assert_allclose(moved[name], expected[name], rtol=0, atol=1e-18, err_msg=name)


def test_the_pins_are_carved_out_conserving_mass_and_first_moments():
    """With the shipped pins: the seven links' total mass and first moment (sum m c) equal the
    five bodies' (pins at their pivots: crank pin at (0, 0, -l3), forearm pin at (l1, 0, 0) in
    base_link's axes, each moving with its neighbour), within 1e-15."""
    carved, bodies = links(P, CONFIG.unprinted, 0.0, RATIOS), links(P, NO_PIN, 0.0, RATIOS)
    pin = CONFIG.unprinted.pin_mass
    assert pin > 0 and carved["crank_pin_link"].mass == pin and carved["forearm_pin_link"].mass == pin
    assert sum(link.mass for link in carved.values()) == pytest.approx(sum(b.mass for b in bodies.values()), rel=1e-15)
    for neighbour, pivot in (("crank_link", (0, 0, -P.l3)), ("lower_bar_link", (P.l1, 0, 0))):
        moment = carved[neighbour].mass * np.array(carved[neighbour].com) + pin * np.array(pivot)
        np.testing.assert_allclose(moment, bodies[neighbour].mass * np.array(bodies[neighbour].com),
                                   rtol=0, atol=1e-15, err_msg=neighbour)
        assert carved[neighbour].mass == pytest.approx(bodies[neighbour].mass - pin, rel=1e-15)


def test_the_records_are_frozen_and_named_as_the_appendix():
    names = [f.name for f in dataclasses.fields(ReportParameters)]
    assert names[:6] == ["l1", "l2", "l3", "l5", "l6", "g"] and len(names) == 23
    with pytest.raises(dataclasses.FrozenInstanceError):
        P.ma = 1.0
    assert [f.name for f in dataclasses.fields(Unprinted)] == ["base_mass", "base_inertia_xx", "base_inertia_zz",
                                                                "pin_mass", "pin_inertia"]
