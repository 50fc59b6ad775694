"""The Phantom's fast paths, written once: the cheap checks of one state (``is_one``, ``finite``),
the per-row map of a Pinocchio function (``rows``) and the 3x3 solves (``solve_spd``,
``accelerations``) in floats, which beat NumPy on 3-vectors."""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Sequence
from typing import Any, TypeGuard, TypeVar

import numpy as np
import pinocchio as pin

from phantom_pin.dynamics.coupling import Coupling

ONE = (3,)
T = TypeVar("T")
#: eigenpy converts boolean arrays, which as_states refuses: the fast paths that check only
#: shapes send them to the checked path (a builtin dtype is one object)
BOOL = np.dtype(bool)
isfinite = math.isfinite


def finite(array: np.ndarray) -> bool:
    """Cheap: True if ``array`` holds no NaN or inf (False also when its sum overflows,
    which only sends the caller to its slow path, where the full checks name the culprit)."""
    return math.isfinite(sum(array.ravel("K").tolist()))


def is_one(value: object) -> TypeGuard[np.ndarray]:
    """The fast paths' check, written once: True if ``value`` is a finite vector of shape (3,)
    (an array; the dtype is left to eigenpy, but for booleans, which eigenpy would take: their
    tolist() gives bools, sent to the checked path, which refuses them by name).

    ``a, b, c = value.tolist() if value.size == 3 else ()`` then ``isfinite(a + b + c)`` is the
    cheapest check (0.16 us, against 0.33 us for a shape comparison and sum()): a batch fails
    to unpack () without being listed (ValueError), as tolist() of a (1, 3) array does; that of
    a (3, 1) array unpacks into lists whose sum isfinite refuses (TypeError), as it refuses
    complex numbers and strings; lists have no size (AttributeError). A sum that overflows only
    sends a finite input to the checked path. Functions of theta alone stay finite on a finite
    theta; where rates enter, whose products can overflow, the caller checks the result too."""
    try:
        a, b, c = value.tolist() if value.size == 3 else ()  # type: ignore[attr-defined,misc]
        return a.__class__ is not bool and isfinite(a + b + c)
    except (AttributeError, TypeError, ValueError):
        return False


def attempt(function: Callable[..., T], *args: Any) -> T | None:
    """``function(*args)``, the fast paths' one try: None where eigenpy refuses a dtype
    (TypeError), which the checked path then converts, or names."""
    try:
        return function(*args)
    except TypeError:
        return None


def rows(function: Callable[..., np.ndarray], *arrays: np.ndarray, before: tuple = (),
          after: tuple = ()) -> np.ndarray:
    """``function(*before, *rows, *after)`` of each row of ``arrays`` (each (N, k)), stacked
    into one new array. map calls a Pinocchio function with its fixed arguments (model,
    data, frame...) in ``before`` and ``after`` without a Python frame per row."""
    fixed = map(itertools.repeat, before), map(itertools.repeat, after)
    return np.array(list(map(function, *fixed[0], *arrays, *fixed[1])))


def solve_spd(m: list[list[float]], r: Sequence[float]) -> tuple[float, float, float] | None:
    """x with m x = r for a symmetric 3x3 ``m`` (nested lists; the upper triangle is read),
    by its adjugate; None unless m is positive definite (Sylvester: leading minors > 0)."""
    (a, b, c), (_, d, e), (_, _, f) = m
    cof_a, cof_b, cof_c = d * f - e * e, c * e - b * f, b * e - c * d
    minor2, det = a * d - b * b, a * cof_a + b * cof_b + c * cof_c
    if not (a > 0 and minor2 > 0 and det > 0):
        return None
    cof_d, cof_e = a * f - c * c, b * c - a * e
    r0, r1, r2 = r
    return ((cof_a * r0 + cof_b * r1 + cof_c * r2) / det,
            (cof_b * r0 + cof_d * r1 + cof_e * r2) / det,
            (cof_c * r0 + cof_e * r1 + minor2 * r2) / det)


def accelerations(mass: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """x with ``mass`` x = ``rhs`` (a symmetric (3, 3) M and (3,) torques): solve_spd, or where M
    is not positive definite (or not finite) Cholesky, which decides, as ever (LinAlgError)."""
    acc = solve_spd(mass.tolist(), rhs.tolist())
    if acc is None:
        factor = np.linalg.cholesky(mass)
        return np.linalg.solve(factor.T, np.linalg.solve(factor, rhs))
    return np.array(acc)


def coriolis(coupling: Coupling, tree_data: pin.Data, q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """The Coriolis matrix of ``coupling``'s reduced model at (q, v): Pinocchio's is silently wrong
    on mimic models (DEVELOPERS.md), so the tree's, projected: C = G^T C_tree G."""
    return coupling.project(pin.computeCoriolisMatrix(coupling.tree, tree_data, coupling.configuration(q),
                                                      coupling.tangent(v)))


def frame_jacobian(name: str, reference: pin.ReferenceFrame, doc: str) -> Callable[..., np.ndarray]:
    """A Phantom method: the tip's frame Jacobian in ``reference`` of the model rooted at
    frame s; a closure, so that its fast path is as short as forward_kinematics'."""
    def method(self: Any, theta: object) -> np.ndarray:
        model, data, tip = self._kinematics, self._kinematics_data, self._frame_tip
        if is_one(theta) and (out := attempt(pin.computeFrameJacobian, model, data, theta, tip, reference)) is not None:
            return out  # the fast path
        return self._each(pin.computeFrameJacobian, ("theta",), theta, before=(model, data),
                          after=(tip, reference))
    method.__name__, method.__qualname__, method.__doc__ = name, f"Phantom.{name}", doc
    return method
