"""The report appendix's numeric Tau1-Tau3 ("Numerical Values"), typed as printed, with rounding bounds.

Each coefficient is kept as its printed string, so that its rounding error (half a unit
in its last printed digit) is known. ``torques`` returns the printed torques and a
rigorous bound on their rounding error: sum over terms of half-ulp * |basis function|.
The appendix computed them with its "Numerical Values" (NUMERICAL_VALUES), which are
section 3's numbers except Iayy = 0.0018e-4, eq. 41's 0.001843e-4 rounded; the YAML holds
eq. 41's. ``applies`` tells whether a set of parameters is the report's, so that the
printed torques apply to it.
"""

from __future__ import annotations

from decimal import Decimal

import numpy as np

from phantom_pin.report.parameters import ReportParameters

#: The appendix's "Numerical Values", as printed (h = 0 omitted), by ReportParameters field name.
NUMERICAL_VALUES = {
    "l1": "0.215", "l2": "0.170", "l3": "0.0325", "l5": "-0.0368", "l6": "0.0527",
    "ma": "0.0202", "Iaxx": "0.4864e-4", "Iayy": "0.0018e-4", "Iazz": "0.4864e-4",
    "mc": "0.0249", "Icxx": "0.959e-4", "Icyy": "0.959e-4", "Iczz": "0.0051e-4",
    "mbe": "0.2359", "Ibexx": "11.09e-4", "Ibeyy": "10.06e-4", "Ibezz": "0.591e-4",
    "mdf": "0.1906", "Idfxx": "7.11e-4", "Idfyy": "0.629e-4", "Idfzz": "6.246e-4",
    "Ibaseyy": "11.87e-4", "g": "9.81",
}
APPENDIX_IAYY = float(NUMERICAL_VALUES["Iayy"])
#: Eq. 41's Iayy (kg m^2), which the appendix rounded to APPENDIX_IAYY.
EQ41_IAYY = 0.001843e-4


def applies(params: ReportParameters) -> bool:
    """True if ``params`` (a ReportParameters) hold the report's numbers: every appendix value,
    with Iayy either the appendix's or eq. 41's. Only then do the printed torques apply."""
    return all(getattr(params, name) == float(text) for name, text in NUMERICAL_VALUES.items()
               if name != "Iayy") and params.Iayy in (APPENDIX_IAYY, EQ41_IAYY)


def _c(text: str) -> tuple[float, float]:
    value = Decimal(text)
    return float(value), float(Decimal(1).scaleb(int(value.as_tuple().exponent))) / 2


def torques(theta: np.ndarray, dtheta: np.ndarray, ddtheta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(printed Tau1..Tau3, bound on their rounding error), each of shape (..., 3), N m."""
    t1, t2, t3 = np.moveaxis(theta, -1, 0)
    d1, d2, d3 = np.moveaxis(dtheta, -1, 0)
    a1, a2, a3 = np.moveaxis(ddtheta, -1, 0)
    s, c = np.sin, np.cos
    # (printed coefficient, basis function) for each term of each torque
    tau1 = [("-0.00905514", d1 * d2 * s(2 * t2) / 4), ("-0.00364919", d1 * d2 * s(t2) * s(t3) / 4),
            ("0.00364919", d1 * d3 * c(t2) * c(t3) / 4), ("0.00312962", d1 * d3 * s(2 * t3) / 4),
            ("0.00283279", a1), ("0.00113189", c(2 * t2) * a1), ("-0.000391203", c(2 * t3) * a1),
            ("0.000912299", c(t2) * s(t3) * a1)]
    tau2 = [("-0.016298", c(t2)), ("0.00905514", s(2 * t2) * d1**2 / 8),
            ("0.00364919", s(t2) * s(t3) * d1**2 / 8), ("0.000456149", c(t2 - t3) * d3**2),
            ("0.0024264", a2), ("-0.000456149", s(t2 - t3) * a3)]
    tau3 = [("-0.0737552", s(t3)), ("-0.00364919", c(t2) * c(t3) * d1**2 / 8),
            ("-0.00312962", s(2 * t3) * d1**2 / 8), ("-0.000456149", c(t2 - t3) * d2**2),
            ("-0.000456149", s(t2 - t3) * a2), ("0.000931886", a3)]
    values, bounds = [], []
    for terms in (tau1, tau2, tau3):
        coefficients = [_c(text) for text, _ in terms]
        values.append(sum(v * basis for (v, _), (_, basis) in zip(coefficients, terms)))
        bounds.append(sum(h * np.abs(basis) for (_, h), (_, basis) in zip(coefficients, terms)))
    return np.stack(values, axis=-1), np.stack(bounds, axis=-1)
