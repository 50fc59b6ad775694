"""Base parameters: the combinations of the parameters that the joint torques determine.

For a regressor stacked over many states, W (3N x P), a QR decomposition with column
pivoting, W P = Q [R1 R2], gives the numerical rank r (|R_kk| > tol |R_11|) and the base
parameters beta = pi_1 + R1^-1 R2 pi_2 (pi_1 the r pivot columns' parameters), with
W pi = W_1 beta for every pi. ``BaseParameters.matrix`` is the map K: beta = K pi.

Two models are used (run ``python -m phantom_pin.identification.structure.structures`` to print both):
the general rigid-body model (structures.General: every standard parameter of the five bodies,
the rotor inertia and the friction, through ``Regressor``'s tree bodies), and the report's
structure (structures.Structured: the report parameters of ``parameterization``, where centres of mass
lie on the segments' axes and the segment axes are principal, plus friction). The second's
rigid-body base is the report's eight constants K1, K2, K3, L, M22, M33 and the gravity
coefficients of eqs 81-94 (``report_constants``).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from phantom_pin import _blas
from phantom_pin.config.sampling import sample_postures
from phantom_pin.identification.structure.regressor import Regressor

#: Relative size of |R_kk| below which a column counts as dependent.
RANK_TOLERANCE = 1e-9
#: Coefficients below this (relative to the largest) are printed and kept as zero.
_ZERO = 1e-7


@dataclasses.dataclass(frozen=True)
class BaseParameters:
    """beta = matrix @ pi. ``independent``: the pivot columns (one per beta); ``names``: pi's."""

    names: tuple[str, ...]
    independent: tuple[int, ...]
    matrix: np.ndarray

    @property
    def rank(self) -> int:
        return len(self.independent)

    def words(self, k: int) -> str:
        """beta_k as a sum, its pivot parameter first, e.g. 'turret_link.Izz + upper_arm_link.Ixx + rotor1 + ...'."""
        return words(self.matrix[k], self.names, self.independent[k])

    def describe(self) -> list[str]:
        return [f"beta{k + 1:<2} = {self.words(k)}" for k in range(self.rank)]


#: The digits (of the largest coefficient) to which words() compares coefficients.
WORD_DIGITS = 9


def words(row: np.ndarray, names: tuple[str, ...] | list[str], first: int | None = None) -> str:
    """A linear combination as a sum, largest coefficients first (``first`` leading), those equal
    to WORD_DIGITS digits in the order of ``names`` (a fixed rule: coefficients of 1 come out of
    the QR as 1 +- 1e-16, in an order the BLAS kernel decided; DEVELOPERS.md)."""
    size = np.round(np.abs(row) / max(float(np.abs(row).max()), 1e-300), WORD_DIGITS)
    keys = -size - (np.arange(len(row)) == first) * 1e300
    terms = []
    for j in np.argsort(keys, kind="stable"):
        if abs(row[j]) > _ZERO * np.abs(row).max():
            coefficient = "" if np.isclose(abs(row[j]), 1.0, rtol=1e-9) else f"{abs(row[j]):.6g} "
            terms.append(f"{'-' if row[j] < 0 else ''}{coefficient}{names[j]}")
    return " + ".join(terms).replace("+ -", "- ")


def base_parameters(stacked: np.ndarray, names: tuple[str, ...] | list[str],
                    scale: np.ndarray | None = None, affine: np.ndarray | None = None) -> BaseParameters:
    """The base parameters of a stacked regressor (3N, P) whose columns are ``names``; of
    ``stacked @ affine`` where ``affine`` is given (the regressor in other parameters).

    ``scale`` (P,), the typical size of each parameter, equilibrates the columns before
    pivoting, so that the pivots are the parameters that matter most. On one BLAS kernel and
    thread (phantom_pin._blas): columns of equal norm (a symmetry's) tie for a pivot, and the
    kernel's rounding chose which (Sandybridge against Haswell: another basis; DEVELOPERS.md).
    """
    return _blas.run(_base_parameters, np.asarray(stacked, float), tuple(names), scale, affine)


def _base_parameters(stacked: np.ndarray, names: tuple[str, ...], scale: np.ndarray | None,
                     affine: np.ndarray | None, _progress: object) -> BaseParameters:
    if affine is not None:
        stacked = stacked @ affine
    scale = np.ones(stacked.shape[1]) if scale is None else np.asarray(scale, float)
    import scipy.linalg  # here: 0.17 s that every command line start paid

    _, r, order = scipy.linalg.qr(stacked * scale, pivoting=True, mode="economic")
    diagonal = np.abs(np.diag(r))
    rank = int(np.sum(diagonal > RANK_TOLERANCE * diagonal[0]))
    r1, r2 = r[:rank, :rank], r[:rank, rank:]
    combination = scipy.linalg.solve_triangular(r1, r2)          # in scaled units
    matrix = np.zeros((rank, stacked.shape[1]))
    matrix[:, order[:rank]] = np.eye(rank)
    matrix[:, order[rank:]] = combination * scale[order[:rank], None] / scale[order[rank:]]
    matrix[np.abs(matrix) < _ZERO * np.abs(matrix).max(axis=1, keepdims=True)] = 0.0
    return BaseParameters(tuple(names), tuple(int(i) for i in order[:rank]), matrix)


def sample(regressor: Regressor, n: int = 300, seed: int = 0) -> tuple[np.ndarray, ...]:
    """``n`` seeded states inside the limits of the regressor's configuration (the box, the
    stops and the coupled stops; rad, rad/s, rad/s^2)."""
    theta = sample_postures(regressor.phantom.config.limits, n, np.random.default_rng(seed), draws=4 * n)
    rng = np.random.default_rng(seed + 1)
    return theta, rng.normal(0, 2, (n, 3)), rng.normal(0, 20, (n, 3))
