"""The report appendix's numeric Tau1-Tau3 ("Numerical Values"), typed as printed, with rounding bounds.

Each coefficient is kept as its printed string, so that its rounding error (half a unit
in its last printed digit) is known. ``torques`` returns the printed torques and a
rigorous bound on their rounding error: sum over terms of half-ulp * |basis function|.
The appendix computed them with Iayy = 0.0018e-4 (its "Numerical Values"); eq. 41 prints
0.001843e-4, which is what the YAML holds: APPENDIX_IAYY lets a test use the appendix's.
"""

from __future__ import annotations

from decimal import Decimal

import numpy as np

APPENDIX_IAYY = 0.0018e-4


def _c(text: str) -> tuple[float, float]:
    value = Decimal(text)
    return float(value), float(Decimal(1).scaleb(value.as_tuple().exponent)) / 2


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
