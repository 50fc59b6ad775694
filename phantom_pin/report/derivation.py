"""Independent SymPy derivation of M, C, N from the report's segment definitions (section 3).

Nothing here is copied from eqs 81-94: each segment is described only by its rotation
(products of exp(w^ theta), eqs 25-28), its centre-of-mass position, mass and inertia
(sections 3.1-3.5); the Lagrangian L = T - V (eqs 76-77) then gives
M = d^2 T / d dtheta^2, C from the Christoffel symbols of M, and N = dV/dtheta. The
result settles each erratum in docs/errata.md. Needs SymPy (the ``test`` extra).
"""

from __future__ import annotations

import functools
from collections.abc import Callable

import numpy as np
import sympy as sp

from phantom_pin.report.parameters import ReportParameters

theta = sp.symbols("theta1:4", real=True)
dtheta = sp.symbols("dtheta1:4", real=True)
#: Symbols of every ReportParameters field that enters the dynamics.
SYMBOLS = {name: sp.Symbol(name, real=True) for name in (
    "l1", "l2", "l3", "l5", "l6", "g", "ma", "Iaxx", "Iayy", "Iazz", "mc", "Icxx", "Icyy",
    "Iczz", "mbe", "Ibexx", "Ibeyy", "Ibezz", "mdf", "Idfxx", "Idfyy", "Idfzz", "Ibaseyy")}


def _exp(axis: tuple[int, int, int], angle: sp.Symbol) -> sp.Matrix:
    """Rodrigues' formula exp(w^ angle) for a unit axis w (eq. 8's e^(w^ theta))."""
    w = sp.Matrix(axis)
    hat = sp.Matrix([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])
    return sp.eye(3) + sp.sin(angle) * hat + (1 - sp.cos(angle)) * hat * hat


def _segments() -> list[tuple[sp.Expr, sp.Matrix, sp.Matrix, sp.Matrix]]:
    """(mass, rotation, COM position, inertia at the COM or rotation point) per segment."""
    s = SYMBOLS
    w1, w2 = (0, 1, 0), (-1, 0, 0)                     # eqs 25-26 (w3 = w2)
    r1, r2, r3 = _exp(w1, theta[0]), _exp(w2, theta[1]), _exp(w2, theta[2])
    diag = sp.diag
    return [
        # A: forearm, hinged at the elbow r1 r2 (0,0,l1), COM half-way down (section 3.1)
        (s["ma"], r1 * r3, r1 * r2 * sp.Matrix([0, 0, s["l1"]]) + r1 * r3 * sp.Matrix([0, -s["l2"] / 2, 0]),
         diag(s["Iaxx"], s["Iayy"], s["Iazz"])),
        # C: lower bar from the crank pin r1 r3 (0,-l3,0), parallel to the upper arm (3.2)
        (s["mc"], r1 * r2, r1 * r3 * sp.Matrix([0, -s["l3"], 0]) + r1 * r2 * sp.Matrix([0, 0, s["l1"] / 2]),
         diag(s["Icxx"], s["Icyy"], s["Iczz"])),
        # BE: turns about the shoulder with theta2, COM at l5 on its z axis (3.3)
        (s["mbe"], r1 * r2, r1 * r2 * sp.Matrix([0, 0, s["l5"]]), diag(s["Ibexx"], s["Ibeyy"], s["Ibezz"])),
        # DF: turns about the shoulder with theta3, COM at l6 on its y axis (3.4)
        (s["mdf"], r1 * r3, r1 * r3 * sp.Matrix([0, s["l6"], 0]), diag(s["Idfxx"], s["Idfyy"], s["Idfzz"])),
    ]


def _time_derivative(expr: sp.Matrix) -> sp.Matrix:
    return sum((sp.diff(expr, q) * dq for q, dq in zip(theta, dtheta)), sp.zeros(*expr.shape))


@functools.lru_cache(maxsize=1)
def derive() -> tuple[sp.Matrix, sp.Matrix, sp.Matrix, sp.Expr]:
    """Symbolic M (3x3), C (3x3), N (3x1) and V from the Lagrangian, in theta, dtheta, SYMBOLS."""
    kinetic = SYMBOLS["Ibaseyy"] * dtheta[0] ** 2 / 2          # segment G (eq. 74)
    potential = sp.Integer(0)
    for mass, rotation, com, inertia in _segments():
        omega_hat = rotation.T * _time_derivative(rotation)    # eqs 37, 48, 57, 67
        omega = sp.Matrix([omega_hat[2, 1], omega_hat[0, 2], omega_hat[1, 0]])
        if mass in (SYMBOLS["mbe"], SYMBOLS["mdf"]):
            # BE and DF: the report's inertia is about the shoulder, which does not move
            kinetic += (omega.T * inertia * omega)[0] / 2
        else:
            velocity = _time_derivative(com)                   # eqs 36, 47
            kinetic += mass * (velocity.T * velocity)[0] / 2 + (omega.T * inertia * omega)[0] / 2
        potential += mass * SYMBOLS["g"] * com[1]             # gravity along -y (eqs 34, 45)
    mass_matrix = sp.hessian(kinetic, dtheta).applyfunc(sp.expand)
    n = 3
    coriolis = sp.zeros(n, n)
    for k in range(n):
        for j in range(n):
            coriolis[k, j] = sum(
                (sp.diff(mass_matrix[k, j], theta[i]) + sp.diff(mass_matrix[k, i], theta[j])
                 - sp.diff(mass_matrix[i, j], theta[k])) / 2 * dtheta[i] for i in range(n))
    gravity = sp.Matrix([sp.diff(potential, q) for q in theta])
    return mass_matrix, coriolis, gravity, potential


@functools.lru_cache(maxsize=4)
def numeric(params: ReportParameters) -> dict[str, Callable[..., np.ndarray]]:
    """NumPy functions mass_matrix(theta), coriolis_matrix(theta, dtheta), gravity(theta)
    of the derived dynamics for one set of parameters (one state each)."""
    mass_matrix, coriolis, gravity, _ = derive()
    subs = {sym: getattr(params, name) for name, sym in SYMBOLS.items()}
    m = sp.lambdify([theta], mass_matrix.subs(subs), "numpy")
    c = sp.lambdify([theta, dtheta], coriolis.subs(subs), "numpy")
    n = sp.lambdify([theta], gravity.subs(subs), "numpy")
    return {
        "mass_matrix": lambda q: np.array(m(q), dtype=float),
        "coriolis_matrix": lambda q, dq: np.array(c(q, dq), dtype=float),
        "gravity": lambda q: np.array(n(q), dtype=float).ravel(),
    }

