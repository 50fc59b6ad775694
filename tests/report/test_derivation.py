"""The independent SymPy derivation against closed_form, and against the printed typos."""

import numpy as np
import pytest

from helpers import REPORT
from phantom_pin.report import closed_form as cf
from phantom_pin.report import derivation  # needs sympy, a test dependency: fail, never skip, without it


@pytest.fixture(scope="module")
def derived():
    return derivation.numeric(REPORT)


def test_derived_dynamics_equal_closed_form(derived, states):
    theta, dtheta, _ = states
    for q, dq in zip(theta, dtheta):
        np.testing.assert_allclose(derived["mass_matrix"](q), cf.mass_matrix(q, REPORT), rtol=0, atol=1e-14)
        np.testing.assert_allclose(derived["coriolis_matrix"](q, dq), cf.coriolis_matrix(q, dq, REPORT),
                                   rtol=0, atol=1e-14)
        np.testing.assert_allclose(derived["gravity"](q), cf.gravity(q, REPORT), rtol=0, atol=1e-14)


def test_the_printed_typos_disagree_with_the_derivation(derived):
    """docs/errata.md E5 and E8: the printed eqs 81 and 82 are not the Lagrangian's."""
    p = REPORT
    q = np.array([0.1, 0.4, 0.7])
    m = derived["mass_matrix"](q)
    printed_m11 = ((4 * p.Iayy + 4 * p.Iaxx + 8 * p.Ibaseyy + 4 * p.Ibeyy + 4 * p.Ibexx + 4 * p.Icyy
                    + 4 * p.Iczz + 4 * p.Idfyy + 4 * p.Idfxx + 4 * p.l1**2 * p.ma + p.l2**2 * p.ma
                    + p.l1**2 * p.mc + 4 * p.l3**2 * p.mc) / 8
                   + (4 * p.Ibeyy - 4 * p.Ibexx + 4 * p.Icyy - 4 * p.Iczz + p.l1**2 * (4 * p.ma + p.mc)) / 8
                   * np.cos(2 * q[1])
                   + (4 * p.Iayy - 4 * p.Iaxx + 4 * p.Idfyy - 4 * p.Idfxx - p.l2**2 * p.ma - 4 * p.l3**2 * p.mc) / 8
                   * np.cos(2 * q[2])
                   + p.l1 * (p.l2 * p.ma + p.l3 * p.mc) * np.cos(q[1]) * np.sin(q[2]))
    printed_m22 = (4 * p.Ibexx + p.Iczz + p.l1**2 * p.ma + p.l1**2 * p.mc) / 4
    assert abs(printed_m11 - m[0, 0]) > 1e-5 and abs(printed_m22 - m[1, 1]) > 1e-4
    assert m[0, 0] == pytest.approx(cf.mass_matrix(q, REPORT)[0, 0], rel=1e-12)
