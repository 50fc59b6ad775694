"""The report's lumped constants as base parameters: tau = Phi(theta, dtheta, ddtheta) beta.

beta = (K1, K2, K3, L, M22, M33 in kg m^2; N2, N3 in N m; viscous1..3 in N m s/rad;
coulomb1..3 in N m). The first eight are the constants of the report's eqs 81-94 (corrected
as closed_form): M11 = K1 + K2/8 cos 2t2 + K3/8 cos 2t3 + L cos t2 sin t3, M22, M33,
M23 = -L/2 sin(t2 - t3), N2 = n2 cos t2, N3 = n3 sin t3. They are linear in the report
parameters (lengths fixed): constants = C x (``constants_matrix``), and they span exactly
the base parameters of the report's structure (tests/identification/structure/test_constants.py).
The friction columns are dtheta_i and sign(dtheta_i) (config.Friction in motion).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from phantom_pin.description.build import Description
from phantom_pin.identification.structure import parameterization
from phantom_pin.identification.structure.cache import cached
from phantom_pin.report import closed_form
from phantom_pin.report.parameters import ReportParameters

#: The report's lumped constants (eqs 81-94), then the friction, in beta's order.
NAMES = ("K1", "K2", "K3", "L", "M22", "M33", "N2", "N3")
FRICTION_NAMES = tuple(f"{kind}{j}" for kind in ("viscous", "coulomb") for j in (1, 2, 3))
#: Units of each entry of beta.
UNITS = ("kg m^2",) * 6 + ("N m",) * 2 + ("N m s/rad",) * 3 + ("N m",) * 3


def report_constants(x: np.ndarray, description: Description) -> np.ndarray:
    """K1, K2, K3, L, M22, M33 (kg m^2), N2, N3 (N m) of the report parameters ``x``, read
    off closed_form's M and N (eqs 81-85, 93-94): M11 = K1 + K2/8 cos 2t2 + K3/8 cos 2t3 +
    L cos t2 sin t3, M23 = -L/2 sin(t2 - t3), N2 = n2 cos t2, N3 = n3 sin t3."""
    p = parameterization.report_parameters(np.asarray(x, float), description.config)
    h = np.pi / 2
    states = np.array([[0, 0, 0], [0, h, 0], [0, 0, h], [0, h / 2, h / 3]])
    m = closed_form.mass_matrix(states, p)
    rows = np.array([[1, np.cos(2 * t2) / 8, np.cos(2 * t3) / 8, np.cos(t2) * np.sin(t3)]
                     for _, t2, t3 in states])
    k1, k2, k3, lam = np.linalg.solve(rows, m[:, 0, 0])
    n = closed_form.gravity([0.0, 0.0, h], p)
    return np.array([k1, k2, k3, lam, m[0, 1, 1], m[0, 2, 2], closed_form.gravity([0.0, 0.0, 0.0], p)[1], n[2]])


def constants_matrix(description: Description) -> np.ndarray:
    """C (8, 20) with report_constants(x) = C x: the constants are linear in x (lengths fixed).
    Unit steps (1 kg, 1 kg m, 1 kg m^2) keep the differences exact to rounding. Cached per
    Description (identification.cache)."""
    def compute() -> np.ndarray:
        x0 = parameterization.report_vector(description.config)
        c0 = report_constants(x0, description)
        columns = []
        for k in range(len(x0)):
            x = x0.copy()
            x[k] += 1.0
            columns.append(report_constants(x, description) - c0)
        return np.stack(columns, axis=1)

    return cached(description, "constants_matrix", compute).copy()


def _unit_parameters(description: Description) -> tuple[ReportParameters, ...]:
    """One ReportParameters per constant whose constants are e_k (x = C^+ e_k), cached."""
    def compute() -> tuple[ReportParameters, ...]:
        pseudo = np.linalg.pinv(constants_matrix(description))
        known = parameterization.report_of(description.config)
        return tuple(_linear_parameters(pseudo[:, k], known) for k in range(len(NAMES)))

    return cached(description, "unit_parameters", compute)


def _linear_parameters(x: np.ndarray, known: ReportParameters) -> ReportParameters:
    """Parameters that closed_form reads linearly in x: mbe and mdf enter closed_form only as
    mbe * l5 and mdf * l6 (eqs 93-94), so they carry the first moments with l5 = l6 = 1 m."""
    values = dict(zip(parameterization.SYMBOLS, x))
    return dataclasses.replace(
        known, ma=values["ma"], Iaxx=values["Iaxx"], Iayy=values["Iayy"], Iazz=values["Iazz"],
        mc=values["mc"], Icxx=values["Icxx"], Icyy=values["Icyy"], Iczz=values["Iczz"],
        mbe=values["mbe*l5"], l5=1.0, Ibexx=values["Ibexx"], Ibeyy=values["Ibeyy"],
        Ibezz=values["Ibezz"], mdf=values["mdf*l6"], l6=1.0, Idfxx=values["Idfxx"],
        Idfyy=values["Idfyy"], Idfzz=values["Idfzz"], Ibaseyy=values["Ibaseyy"])


def regressor(theta: np.ndarray, dtheta: np.ndarray, ddtheta: np.ndarray,
              description: Description) -> np.ndarray:
    """Phi (..., 3, 14) from closed_form's inverse dynamics, one constant at a time (vectorised);
    the friction columns are dtheta_i and sign(dtheta_i), the terms of the description's
    friction law (Friction.torque with unit coefficients)."""
    columns = [closed_form.inverse_dynamics(theta, dtheta, ddtheta, p) for p in _unit_parameters(description)]
    dtheta = np.asarray(dtheta, float)
    law = description.config.actuation.friction
    eye = np.eye(3)
    viscous = dtheta[..., :, None] * eye
    coulomb = law.unit_coulomb().torque(dtheta)[..., :, None] * eye
    return np.concatenate([np.stack(columns, axis=-1), viscous, coulomb], axis=-1)


def nominal(description: Description) -> np.ndarray:
    """beta of a configuration: its report constants and its friction (viscous1..3, coulomb1..3)."""
    law = description.config.actuation.friction
    return np.concatenate([report_constants(parameterization.report_vector(description.config), description),
                           law.viscous, law.coulomb])
