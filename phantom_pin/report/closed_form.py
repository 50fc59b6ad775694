"""The report's closed-form kinematics and dynamics (eqs 10-24, 80-94), corrected, in NumPy.

Every function takes one state (shape (3,)) or a batch (shape (..., 3)) and the report's
numbers (``params``: a ReportParameters, e.g. phantom_pin.config.read().report), and returns
fresh arrays with the same leading axes. Angles are the report's theta1..theta3 (rad);
positions are in metres in the report's kinematic frame s (x left, y up, z forward,
origin at the tip of the zero configuration); torques in N m. The printed equations
contain typos; the corrections, and their evidence, are listed in docs/errata.md.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Protocol

import numpy as np

from phantom_pin._validation import as_states, finite_result, same_batch, wrap_angle
from phantom_pin.exceptions import InvalidInputError, UnreachableTargetError
from phantom_pin.report.parameters import ReportParameters

#: Relative slack on the law-of-cosines arguments before a target counts as unreachable.
_ACOS_SLACK = 1e-12
#: States per chunk of the batched dynamics: the NumPy temporaries of a chunk fit in cache.
_CHUNK = 8192


def _state(theta: object, name: str = "theta") -> tuple[np.ndarray, ...]:
    array, _ = as_states(theta, name)
    return array[..., 0], array[..., 1], array[..., 2]


def forward_kinematics(theta: object, params: ReportParameters) -> np.ndarray:
    """Pose g_st of the tool frame t in frame s, eq. 10: shape (..., 4, 4), metres."""
    p = params
    t1, t2, t3 = _state(theta)
    s1, c1, s2, c2, s3, c3 = np.sin(t1), np.cos(t1), np.sin(t2), np.cos(t2), np.sin(t3), np.cos(t3)
    reach = p.l1 * c2 + p.l2 * s3
    g = np.zeros(t1.shape + (4, 4))
    g[..., 0, :] = np.stack([c1, -s1 * s3, c3 * s1, s1 * reach], axis=-1)
    g[..., 1, :] = np.stack([0 * t1, c3, s3, p.l2 - p.l2 * c3 + p.l1 * s2], axis=-1)
    g[..., 2, :] = np.stack([-s1, -c1 * s3, c1 * c3, -p.l1 + c1 * reach], axis=-1)
    g[..., 3, 3] = 1.0
    return g


class Lengths(Protocol):
    """What the inverse kinematics reads (m): the upper arm l1 and the forearm l2, of
    ReportParameters or of a Config's Kinematics."""

    @property
    def l1(self) -> float: ...

    @property
    def l2(self) -> float: ...


def inverse_kinematics(position: object, params: Lengths, branch: str = "report") -> np.ndarray:
    """Joint angles (rad) that put the tip at ``position`` (m, frame s), eqs 11-20.

    ``branch="report"`` is the report's elbow branch (gamma > 0, alpha > 0:
    theta2 = gamma + beta, theta3 = theta2 + alpha - pi/2), the one the Phantom's
    parallelogram reaches. ``branch="other"`` is the mirrored elbow
    (theta2 = beta - gamma, theta3 = theta2 - alpha - pi/2). Raises
    UnreachableTargetError when a target is farther from the shoulder than l1 + l2
    or nearer than |l1 - l2|. Angles are wrapped into (-pi, pi] (theta1 = +pi behind
    the shoulder); they may lie outside the joint limits.
    """
    p = params
    if branch not in ("report", "other"):
        raise InvalidInputError(f"expected 'report' or 'other', got {branch!r}", argument="branch")
    target, _ = as_states(position, "position")
    px, py, pz = target[..., 0], target[..., 1], target[..., 2]
    theta1 = np.arctan2(px, pz + p.l1)                              # eq 11
    horizontal = np.hypot(px, pz + p.l1)                            # eq 12
    r = np.sqrt(horizontal**2 + (py - p.l2) ** 2)                   # eq 13
    beta = np.arctan2(py - p.l2, horizontal)                        # eq 14
    with np.errstate(divide="ignore", invalid="ignore"):
        cos_gamma = (p.l1**2 + r**2 - p.l2**2) / (2 * p.l1 * r)     # eq 16
        cos_alpha = (p.l1**2 + p.l2**2 - r**2) / (2 * p.l1 * p.l2)  # eq 19
    bad = ~(np.abs(cos_gamma) <= 1 + _ACOS_SLACK) | ~(np.abs(cos_alpha) <= 1 + _ACOS_SLACK)
    if np.any(bad):
        first = np.asarray(target)[bad][0] if target.ndim > 1 else target
        raise UnreachableTargetError(
            f"{np.array2string(first, precision=4)} m is outside the reachable "
            f"shell {abs(p.l1 - p.l2):.4f} m <= distance from the shoulder <= {p.l1 + p.l2:.4f} m", argument="position")
    gamma = np.arccos(np.clip(cos_gamma, -1.0, 1.0))
    alpha = np.arccos(np.clip(cos_alpha, -1.0, 1.0))
    if branch == "report":
        theta2 = gamma + beta                                       # eq 17
        theta3 = theta2 + alpha - np.pi / 2                         # eq 20
    else:
        theta2 = beta - gamma
        theta3 = theta2 - alpha - np.pi / 2
    return wrap_angle(np.stack([theta1, theta2, theta3], axis=-1))


def spatial_jacobian(theta: object, params: ReportParameters) -> np.ndarray:
    """Spatial manipulator Jacobian J^s, eq. 22: shape (..., 6, 3), twist order (v, omega).

    Columns map joint rates (rad/s) to the spatial twist of the tool in frame s
    (v in m/s: the velocity of the body point at the origin of s; omega in rad/s).
    """
    p = params
    t1, t2, t3 = _state(theta)
    s1, c1, s2, c2 = np.sin(t1), np.cos(t1), np.sin(t2), np.cos(t2)
    zero, one = 0 * t1, 0 * t1 + 1
    rows = [
        [p.l1 * one, -p.l1 * s1 * s2, s1 * (p.l2 + p.l1 * s2)],
        [zero, p.l1 * c2, p.l1 * (c1 - c2)],
        [zero, -p.l1 * c1 * s2, c1 * (p.l2 + p.l1 * s2)],
        [zero, zero, -c1],
        [one, zero, zero],
        [zero, zero, s1],
    ]
    return np.stack([np.stack(row, axis=-1) for row in rows], axis=-2)


def body_jacobian(theta: object, params: ReportParameters) -> np.ndarray:
    """Body manipulator Jacobian J^b, eq. 24: shape (..., 6, 3), twist order (v, omega).

    Columns map joint rates (rad/s) to the tool's body twist in frame t (m/s, rad/s).
    """
    p = params
    t1, t2, t3 = _state(theta)
    zero = 0 * t1
    rows = [
        [p.l1 * np.cos(t2) + p.l2 * np.sin(t3), zero, zero],
        [zero, p.l1 * np.cos(t2 - t3), zero],
        [zero, -p.l1 * np.sin(t2 - t3), p.l2 + zero],
        [zero, zero, zero - 1],
        [np.cos(t3), zero, zero],
        [np.sin(t3), zero, zero],
    ]
    return np.stack([np.stack(row, axis=-1) for row in rows], axis=-2)


def _coefficients(p: ReportParameters) -> tuple[float, float, float, float]:
    """K1, K2, K3, L of eqs 81-92 with the zz corrections of docs/errata.md (E5-E7)."""
    k1 = (4 * p.Iayy + 4 * p.Iazz + 8 * p.Ibaseyy + 4 * p.Ibeyy + 4 * p.Ibezz + 4 * p.Icyy
          + 4 * p.Iczz + 4 * p.Idfyy + 4 * p.Idfzz + 4 * p.l1**2 * p.ma + p.l2**2 * p.ma
          + p.l1**2 * p.mc + 4 * p.l3**2 * p.mc) / 8
    k2 = 4 * p.Ibeyy - 4 * p.Ibezz + 4 * p.Icyy - 4 * p.Iczz + p.l1**2 * (4 * p.ma + p.mc)
    k3 = 4 * p.Iayy - 4 * p.Iazz + 4 * p.Idfyy - 4 * p.Idfzz - p.l2**2 * p.ma - 4 * p.l3**2 * p.mc
    return k1, k2, k3, p.l1 * (p.l2 * p.ma + p.l3 * p.mc)


class _Trig:
    """sin and cos of theta2, theta3 (rad), evaluated once for every equation below; the
    double and difference angles by their identities."""

    def __init__(self, t2: np.ndarray, t3: np.ndarray) -> None:
        self.s2, self.c2, self.s3, self.c3 = np.sin(t2), np.cos(t2), np.sin(t3), np.cos(t3)

    def sin_2(self) -> np.ndarray:       # sin 2 theta2
        return 2 * self.s2 * self.c2

    def cos_2(self) -> np.ndarray:       # cos 2 theta2
        return 1 - 2 * self.s2 * self.s2

    def sin_3(self) -> np.ndarray:       # sin 2 theta3
        return 2 * self.s3 * self.c3

    def cos_3(self) -> np.ndarray:       # cos 2 theta3
        return 1 - 2 * self.s3 * self.s3

    def sin_23(self) -> np.ndarray:      # sin(theta2 - theta3)
        return self.s2 * self.c3 - self.c2 * self.s3

    def cos_23(self) -> np.ndarray:      # cos(theta2 - theta3)
        return self.c2 * self.c3 + self.s2 * self.s3


# The equations, each written once as its nonzero entries {(row, column): value}; the
# functions below assemble matrices from them, and inverse_dynamics sums them per component
# (no (N, 3, 3) intermediates: a batch runs at NumPy's speed on (N,) arrays).

def _mass_entries(trig: _Trig, p: ReportParameters) -> dict[tuple[int, int], np.ndarray | float]:
    k1, k2, k3, lam = _coefficients(p)
    m12 = -lam / 2 * trig.sin_23()                                                  # eqs 83-84
    return {
        (0, 0): k1 + k2 / 8 * trig.cos_2() + k3 / 8 * trig.cos_3() + lam * trig.c2 * trig.s3,  # eq 81
        (1, 1): p.Ibexx + p.Icxx + p.l1**2 * p.ma + p.l1**2 * p.mc / 4,             # eq 82 (E8)
        (1, 2): m12, (2, 1): m12,
        (2, 2): p.Iaxx + p.Idfxx + p.l2**2 * p.ma / 4 + p.l3**2 * p.mc,             # eq 85
    }


def _coriolis_entries(trig: _Trig, d1: np.ndarray, d2: np.ndarray, d3: np.ndarray,
                      p: ReportParameters) -> dict[tuple[int, int], np.ndarray]:
    _, k2, k3, lam = _coefficients(p)
    # a = (k2 sin 2theta2 + 4 L sin theta2 sin theta3) / 8, b = (4 L cos theta2 cos theta3
    # - k3 sin 2theta3) / 8, with sin 2x = 2 sin x cos x, factored
    a = trig.s2 * (k2 / 4 * trig.c2 + lam / 2 * trig.s3)
    b = trig.c3 * (lam / 2 * trig.c2 - k3 / 4 * trig.s3)
    h = lam / 2 * trig.cos_23()
    a_d1, b_d1 = a * d1, b * d1
    return {
        (0, 0): b * d3 - a * d2,                                                    # eq 86
        (0, 1): -a_d1,                                                              # eq 87
        (0, 2): b_d1,                                                               # eq 88
        (1, 0): a_d1,                                                               # eq 89
        (1, 2): h * d3,                                                             # eq 90
        (2, 0): -b_d1,                                                              # eq 91
        (2, 1): -h * d2,                                                            # eq 92
    }


def _gravity_entries(trig: _Trig, p: ReportParameters) -> dict[int, np.ndarray]:
    return {1: p.g / 2 * (2 * p.l1 * p.ma + 2 * p.l5 * p.mbe + p.l1 * p.mc) * trig.c2,  # eq 93
            2: p.g / 2 * (p.l2 * p.ma + 2 * p.l3 * p.mc - 2 * p.l6 * p.mdf) * trig.s3}  # eq 94


def _matrix(entries: Mapping[tuple[int, int], np.ndarray | float], shape: tuple[int, ...]) -> np.ndarray:
    out = np.zeros(shape + (3, 3))
    for (i, j), value in entries.items():
        out[..., i, j] = value
    return out


def mass_matrix(theta: object, params: ReportParameters) -> np.ndarray:
    """Joint-space inertia matrix M(theta), eqs 81-85 (corrected): (..., 3, 3), kg m^2.

    Includes the motors' reflected rotor inertia, lumped by the report into Ibexx,
    Idfxx and Ibaseyy.
    """
    p = params
    _, t2, t3 = _state(theta)
    return _matrix(_mass_entries(_Trig(t2, t3), p), t2.shape)


def coriolis_matrix(theta: object, dtheta: object, params: ReportParameters) -> np.ndarray:
    """Coriolis/centrifugal matrix C(theta, dtheta), eqs 86-92 (corrected): (..., 3, 3).

    In N m s/rad; C(theta, dtheta) @ dtheta is the velocity-product torque, and
    dM/dt - 2C is skew-symmetric (C is built from the Christoffel symbols of M).
    """
    p = params
    _, t2, t3 = _state(theta)
    d1, d2, d3 = _state(dtheta, "dtheta")
    same_batch(("theta", "dtheta"), t2, d1)
    return _matrix(_coriolis_entries(_Trig(t2, t3), d1, d2, d3, p), t2.shape)


def gravity(theta: object, params: ReportParameters) -> np.ndarray:
    """Gravity torque N(theta), eqs 93-94: shape (..., 3), N m (N1 = 0)."""
    p = params
    _, t2, t3 = _state(theta)
    n = np.zeros(t2.shape + (3,))
    for i, value in _gravity_entries(_Trig(t2, t3), p).items():
        n[..., i] = value
    return n


def potential_energy(theta: object, params: ReportParameters) -> np.ndarray:
    """Potential energy V = V_a + V_c + V_be + V_df (eqs 34, 45, 55, 65), J; zero at the shoulder."""
    p = params
    _, t2, t3 = _state(theta)
    s2, c3 = np.sin(t2), np.cos(t3)
    return p.g * (p.ma * (p.l1 * s2 - p.l2 / 2 * c3) + p.mc * (p.l1 / 2 * s2 - p.l3 * c3)
                  + p.mbe * p.l5 * s2 + p.mdf * p.l6 * c3)


def inverse_dynamics(theta: object, dtheta: object, ddtheta: object,
                     params: ReportParameters) -> np.ndarray:
    """Joint torques tau = M ddtheta + C dtheta + N, eq. 80: shape (..., 3), N m.

    theta in rad, dtheta in rad/s, ddtheta in rad/s^2.
    """
    p = params
    acc, _ = as_states(ddtheta, "ddtheta")
    vel, _ = as_states(dtheta, "dtheta")
    pos, _ = as_states(theta, "theta")
    same_batch(("theta", "dtheta", "ddtheta"), pos, vel, acc)
    flat = [x.reshape(-1, 3) for x in (pos, vel, acc)]
    tau = np.empty(flat[0].shape)
    with np.errstate(over="ignore", invalid="ignore"):  # reported by finite_result
        for start in range(0, len(tau), _CHUNK):  # chunks: the temporaries stay in cache
            t, d, a = (np.ascontiguousarray(x[start:start + _CHUNK].T) for x in flat)
            trig = _Trig(t[1], t[2])
            out = np.zeros(t.shape)
            for (i, j), value in _mass_entries(trig, p).items():
                out[i] += value * a[j]
            for (i, j), value in _coriolis_entries(trig, d[0], d[1], d[2], p).items():
                out[i] += value * d[j]
            for i, value in _gravity_entries(trig, p).items():
                out[i] += value
            tau[start:start + _CHUNK] = out.T
    return finite_result(tau.reshape(pos.shape), "theta, dtheta, ddtheta")
