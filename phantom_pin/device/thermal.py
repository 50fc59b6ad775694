"""The motors' two torque limits over time: the peak for short forces, the continuous rating on
average.

A DC motor's winding heats as the square of its current, so as tau^2; its temperature follows
the mean of tau^2 over the winding's thermal time constant T (actuation.yaml's
motor.thermal_time_constant: 12.0 s for the Premium 1.5's maxon RE 25). The continuous rating
tau_c is the torque whose square, held, brings the winding to its limit. So a command is
clipped, joint by joint, to the peak (stall) torque tau_p and to what keeps the exponential
average e of tau^2 (e += alpha (tau^2 - e) each period, alpha = 1 - exp(-period / T)) at or
below tau_c^2:

    |tau| <= min(tau_p, sqrt(max(tau_c^2, e + (tau_c^2 - e) / alpha)))

From cold a stall-torque command lasts -T ln(1 - tau_c^2 / tau_p^2) (0.60 s on the Premium 1.5:
its 7.98-8.80 N peak tip force, docs/feel.md), then the continuous torque holds it (1.47-1.95
N). A model without motor data (the Touch) has one limit for both: the clip is that limit.
"""

from __future__ import annotations

import math

import numpy as np

from phantom_pin.device.device import Device
from phantom_pin.exceptions import InvalidInputError


class TorqueBudget:
    """``clip(tau)`` or ``scale(tau)`` (N m, (3,)) once per servo period of ``period`` s (an
    attribute: a loop whose period varies sets it before the call): the torque the motors may
    give now (module doc), the winding's average updated with it. Starts cold (e = 0)."""

    def __init__(self, device: Device, period: float = 1e-3) -> None:
        if isinstance(period, bool) or not isinstance(period, (int, float)) or not 0 < period < math.inf:
            raise InvalidInputError(f"expected a period > 0 s, got {period!r}", argument="period")
        actuation = device.config.actuation
        self.peak = np.array(actuation.limit("peak"))
        self.continuous = np.array(actuation.limit("continuous"))
        self.time_constant = None if actuation.motor is None else actuation.motor.thermal_time_constant
        self.period = float(period)
        self.mean_square = np.zeros(3)

    @property
    def alpha(self) -> float:
        """The average's gain per period, 1 - exp(-period / T) (1 without motor data)."""
        return 1.0 if self.time_constant is None else 1.0 - math.exp(-self.period / self.time_constant)

    def allowed(self) -> np.ndarray:
        """The largest |tau| (N m) per joint this period."""
        c2 = self.continuous ** 2
        return np.minimum(self.peak, np.sqrt(np.maximum(c2, self.mean_square + (c2 - self.mean_square) / self.alpha)))

    def clip(self, tau: np.ndarray) -> np.ndarray:
        """``tau`` clipped to allowed(), the average then updated with what was given."""
        limit = self.allowed()
        given = np.clip(tau, -limit, limit)
        self.mean_square = self.mean_square + self.alpha * (given ** 2 - self.mean_square)
        return given

    def scale(self, tau: np.ndarray) -> float:
        """The largest s <= 1 with every |s tau_i| within allowed() (a force's direction kept), the
        average then updated with s tau."""
        limit, magnitude = self.allowed(), np.abs(tau)
        over = magnitude > limit
        s = float(min(1.0, *(limit[over] / magnitude[over]))) if over.any() else 1.0
        self.mean_square = self.mean_square + self.alpha * ((s * tau) ** 2 - self.mean_square)
        return s
