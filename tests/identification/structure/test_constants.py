"""identification.structure.constants: the report's lumped constants (eqs 81-94) of the report
parameters against the report's equations written out, their matrix C against closed_form's
inverse dynamics at other parameters, and the closed-form regressor against Pinocchio's."""

import dataclasses

import numpy as np

from helpers import CONFIG, REPORT, seeded_states
from phantom_pin import Phantom
from phantom_pin.identification.structure import constants
from phantom_pin.identification.structure import parameterization as pz
from phantom_pin.identification.structure.regressor import Regressor
from phantom_pin.identification.structure.structures import Report
from phantom_pin.report import closed_form

REGRESSOR = Regressor(Phantom())
DESCRIPTION = REGRESSOR.phantom.description


def test_constants_equal_the_report_equations_at_the_shipped_values():
    p = REPORT
    k1, k2, k3, lam = closed_form._coefficients(p)
    expected = [k1, k2, k3, lam, p.Ibexx + p.Icxx + p.l1**2 * p.ma + p.l1**2 * p.mc / 4,     # eq 82
                p.Iaxx + p.Idfxx + p.l2**2 * p.ma / 4 + p.l3**2 * p.mc,                     # eq 85
                p.g / 2 * (2 * p.l1 * p.ma + 2 * p.l5 * p.mbe + p.l1 * p.mc),               # eq 93
                p.g / 2 * (p.l2 * p.ma + 2 * p.l3 * p.mc - 2 * p.l6 * p.mdf)]               # eq 94
    x0 = pz.report_vector(CONFIG)
    np.testing.assert_allclose(constants.report_constants(x0, DESCRIPTION), expected, rtol=1e-12)
    np.testing.assert_allclose(constants.constants_matrix(DESCRIPTION) @ x0, expected, rtol=1e-12)


def test_pinocchio_base_regressor_equals_the_closed_form_one():
    theta, dtheta, ddtheta = seeded_states(REGRESSOR, 200, 7)
    phi, tau0 = Report(REGRESSOR.phantom).regressor_of(theta, dtheta, ddtheta)
    closed = constants.regressor(theta, dtheta, ddtheta, DESCRIPTION)
    assert np.abs(phi - closed).max() <= 1e-11 * np.abs(closed).max()
    beta = constants.nominal(DESCRIPTION)
    friction = 5e-4 * dtheta + 0.01 * np.sign(dtheta)
    tau = closed_form.inverse_dynamics(theta, dtheta, ddtheta, REPORT) + friction
    assert np.abs(phi @ beta + tau0 - tau).max() <= 1e-12 * np.abs(tau).max()


def test_constants_follow_other_parameters():
    """report_constants is linear in x: C x at perturbed parameters equals closed_form's."""
    p = REPORT
    q = dataclasses.replace(p, ma=1.3 * p.ma, Ibeyy=0.8 * p.Ibeyy, mdf=1.2 * p.mdf, l6=0.9 * p.l6)
    x = np.array([q.ma, q.Iaxx, q.Iayy, q.Iazz, q.mc, q.Icxx, q.Icyy, q.Iczz, q.mbe, q.mbe * q.l5,
                  q.Ibexx, q.Ibeyy, q.Ibezz, q.mdf, q.mdf * q.l6, q.Idfxx, q.Idfyy, q.Idfzz,
                  q.Ibaseyy, CONFIG.actuation.motor.rotor_inertia])
    theta, dtheta, ddtheta = seeded_states(REGRESSOR, 50, 8)
    phi = constants.regressor(theta, dtheta, ddtheta, DESCRIPTION)[..., :8]
    tau = closed_form.inverse_dynamics(theta, dtheta, ddtheta, q)
    assert np.abs(phi @ (constants.constants_matrix(DESCRIPTION) @ x) - tau).max() <= 1e-12 * np.abs(tau).max()
