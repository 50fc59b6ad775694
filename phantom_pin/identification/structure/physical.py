"""Physical consistency of identified parameters, and the nearest consistent parameters to an
estimate.

A link is physical when its pseudo-inertia J = [[Sigma, h], [h^T, m]] (Sigma = integral(r r^T
dm) = tr(I)/2 1 - I about the link origin, h = m c) is positive definite: m > 0 and principal
moments at the centre of mass strictly inside the triangle inequality (Wensing, Kim and
Slotine, IEEE RA-L 2018). J is linear in the standard parameters, so the physical parameters
form a convex set, and the nearest of them to an estimate in any quadratic metric is a convex
problem: ``nearest`` solves it by a log-det barrier (interior point) method whose Newton steps
do not mind the metric's conditioning (the torques fix some combinations to 1e-8 and leave
others to a prior). The decision stays with the one physical check of a link
(phantom_pin.description.inertial.problem), which asks a margin of TRIANGLE_SLACK inside the boundary; the
barrier keeps a margin of its own that implies it (``margined``), so that its optimum passes the
check by construction.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from phantom_pin.config import Config
from phantom_pin.description.inertial import TRIANGLE_SLACK, problem
from phantom_pin.exceptions import InvalidInputError
from phantom_pin.identification.structure import parameterization
from phantom_pin.report.parameters import links

#: The barrier method's end: the duality gap (in units of the whitened cost, a chi-square). The
#: cost sees a direction the data cannot see only through the prior (prior_weight^2 = 1e-6 of
#: its typical size squared), so there the barrier's point at a finite weight lies off the
#: optimum by up to sqrt(gap) / prior_weight of the typical size, at a place the metric's
#: rounding moves (the covariance's conditioning leaves its stiff directions 1e-7 apart for logs
#: a rounding apart). Issue 42, L14, measured: with a gap of 1e-7 the written link numbers were
#: up to 7 % of their typical size off the optimum, and one log identified in two conventions
#: up to 0.3 % (OpenHaptics' CSV) and 16 % (a bag, read back within 1e-9 s) of its link's size
#: apart; with 1e-15, 7e-10 and 6e-8 (tests/identification/data/test_bags.py), the bodies and the check's
#: margin in the barrier (margined), for 0.65 times the CPU (the blocks evaluated at once).
GAP = 1e-15
#: Newton steps per barrier weight, and the weight's growth.
NEWTON_STEPS, GROWTH = 60, 10.0
#: The Newton decrement below which a full step is taken (the quadratic phase: the function,
#: weight x cost + the log-det barrier, is self-concordant, so the full step stays inside the
#: domain and the decrement falls quadratically); the phase ends where it no longer falls
#: (rounding), not in a line search that rounding defeats at large weights.
QUADRATIC = 0.1
#: The barrier's margin (``margined``): J - MARGIN tr(Sigma) diag(1, 1, 1, 0) positive definite
#: gives a triangle slack above 2 MARGIN, twice the check's.
MARGIN = TRIANGLE_SLACK


def consistent(x: np.ndarray, config: Config) -> bool:
    """True if the report parameters ``x`` give links (report.parameters.links, as describe()
    computes them from the written overlay) that all pass phantom_pin.description.inertial.problem, with
    positive masses and rotor inertia x[ROTOR] (zero, without public motor data: Actuation.rotor)."""
    x = np.asarray(x, float)
    rotor = x[parameterization.ROTOR]
    if not ((rotor > 0 if config.actuation.motor else rotor == 0) and (x[list(parameterization.MASSES)] > 0).all()):
        return False
    if config.unprinted is None:
        raise InvalidInputError("the report's structure needs a model in the report's form", argument="config")
    linked = links(parameterization.report_parameters(x, config), config.unprinted, float(rotor),
                   config.actuation.rotor[1])
    return all(problem(link) is None for link in linked.values())


def pseudo_inertia(pi: np.ndarray) -> np.ndarray:
    """The 4x4 pseudo-inertia J of one body's standard parameters (Pinocchio's order [m, m c,
    I_origin xx, xy, yy, xz, yz, zz]; module doc); linear in them."""
    m, hx, hy, hz, ixx, ixy, iyy, ixz, iyz, izz = np.asarray(pi, float)
    inertia = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
    out = np.empty((4, 4))
    out[:3, :3] = 0.5 * np.trace(inertia) * np.eye(3) - inertia
    out[:3, 3] = out[3, :3] = (hx, hy, hz)
    out[3, 3] = m
    return out


def margined(j: np.ndarray) -> np.ndarray:
    """The pseudo-inertia ``j`` less MARGIN tr(Sigma) on Sigma's diagonal: linear in j, so the
    bodies whose margined J is positive definite are still a convex set. It is positive definite
    exactly when m > 0 and the second moments at the centre of mass Sigma_c = Sigma - h h^T / m
    exceed MARGIN tr(Sigma) >= MARGIN tr(Sigma_c) >= MARGIN c (c the largest principal moment,
    tr(Sigma_c) less the smallest second moment); the triangle slack (a + b - c) / c is twice the
    smallest second moment over c, so above 2 MARGIN = 2 TRIANGLE_SLACK, and the margin in units
    of tr(Sigma) (m |c|^2 with the rest) also covers the rounding of the check's parallel-axis
    step. Measured (issue 42, L14; the identification tests' 60 projections): with no margin 9
    barrier ends at GAP = 1e-15 lay within rounding of the boundary (J's smallest eigenvalue
    1e-16 of its largest) and failed the check, with it none."""
    out = np.array(j, float)
    out[:3, :3] -= MARGIN * np.trace(out[:3, :3]) * np.eye(3)
    return out


def nearest(target: np.ndarray, weights: np.ndarray, matrix: np.ndarray, prior: np.ndarray,
            scale: np.ndarray, bodies: Sequence[tuple[np.ndarray, np.ndarray]], positive: Sequence[int],
            consistent: Callable[[np.ndarray], bool], fixed: Sequence[int] = (),
            prior_weight: float = 1e-3) -> np.ndarray:
    """The parameters x nearest to the estimated base parameters ``target``:

        minimise |W (matrix x - target)|^2 + prior_weight^2 |(x - prior) / scale|^2

    subject to every body physical, its standard parameters ``A x + b`` for each (A, b) of
    ``bodies``, and x_i > 0 for i in ``positive``; the entries ``fixed`` stay at the prior.
    ``weights`` W is a matrix with W^T W = the inverse covariance of ``target`` (or a vector:
    its diagonal). The prior (the model's own values, consistent) fixes the directions the data
    cannot see; its weight is small so that it does not move the identifiable combinations
    measurably. The unconstrained optimum if it is ``consistent``; else the barrier method's
    optimum (module doc), stepped back towards the prior as far as ``consistent`` needs."""
    weights = np.diag(weights) if np.ndim(weights) == 1 else np.asarray(weights)
    prior, scale = np.asarray(prior, float), np.asarray(scale, float)
    whitened = _Whitened(target, weights, matrix, prior, scale, np.asarray(fixed, int), prior_weight)
    if consistent(whitened.full(whitened.optimum)):
        return whitened.full(whitened.optimum)
    barrier = _Barrier(whitened, bodies, positive)
    x = whitened.full(_barrier_method(barrier, whitened))
    if consistent(x):
        return x
    low, high = 0.0, 1.0          # not met (``margined`` and the bodies keep it off): step back
    for _ in range(60):
        middle = (low + high) / 2
        if consistent(prior + middle * (x - prior)):
            low = middle
        else:
            high = middle
    return prior + low * (x - prior)


class _Whitened:
    """nearest's cost in z = x / scale over the free entries: 0.5 |K z - k|^2, K = [W matrix scale;
    pw 1]. Its singular value decomposition K = U S V^T whitens it, y = S V^T z: 0.5 |y - y_u|^2
    (no normal equations: the metric spans 1e-6 to 1e18); ``optimum`` is y_u, ``to_z`` maps y to
    z, ``full(y)`` is the parameters x of y (the fixed entries at the prior), ``at_prior`` the y
    of the prior."""

    def __init__(self, target: np.ndarray, weights: np.ndarray, matrix: np.ndarray, prior: np.ndarray,
                 scale: np.ndarray, held: np.ndarray, prior_weight: float) -> None:
        self.prior, self.scale = prior, scale
        self.free = free = np.setdiff1d(np.arange(len(prior)), held)
        z0 = prior / scale
        d = weights @ matrix * scale
        stacked = np.vstack([d[:, free], prior_weight * np.eye(len(free))])
        rhs = np.concatenate([weights @ target - d[:, held] @ z0[held], prior_weight * z0[free]])
        u, sizes, vt = np.linalg.svd(stacked, full_matrices=False)
        self.to_z = vt.T / sizes                                       # z = to_z @ y
        self.optimum = u.T @ rhs                                       # y_u
        self.at_prior = vt @ z0[free] * sizes

    def full(self, y: np.ndarray) -> np.ndarray:
        out = self.prior.copy()
        out[self.free] = (self.to_z @ y) * self.scale[self.free]
        return out

    def cost(self, y: np.ndarray) -> float:
        return float(0.5 * (y - self.optimum) @ (y - self.optimum))


class _Barrier:
    """-log det of every body's margined pseudo-inertia J (``margined``) - log z_i of the positive
    entries, over y (_Whitened); each J as C + sum_j y_j B_j, all bodies at once (``bases``
    (bodies, len(y), 4, 4), ``constants`` (bodies, 4, 4)). ``size``: the number of barrier terms
    (4 a body)."""

    def __init__(self, whitened: _Whitened, bodies: Sequence[tuple[np.ndarray, np.ndarray]],
                 positive: Sequence[int]) -> None:
        free, scale, to_z = whitened.free, whitened.scale, whitened.to_z
        bases, constants = [], []
        for a, b in bodies:
            a = np.asarray(a, float)[:, free] * scale[free] @ to_z
            if np.abs(a).max() > 0:
                bases.append([margined(pseudo_inertia(column)) for column in a.T])
                constants.append(margined(pseudo_inertia(b)))
        self.bases = np.array(bases).reshape(len(bases), len(to_z.T), 4, 4)
        self.constants = np.array(constants).reshape(len(constants), 4, 4)
        self.rows = to_z[[list(free).index(i) for i in positive if i in free]]      # z_i = rows @ y > 0
        self.size = 4 * len(self.bases) + len(self.rows)

    def _roots(self, y: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
        """(every J, its Cholesky factor) at ``y``; None outside the domain (a J not positive
        definite, to rounding)."""
        j = self.constants + np.einsum("j,bjkl->bkl", y, self.bases)
        try:
            return j, np.linalg.cholesky(j)
        except np.linalg.LinAlgError:
            return None

    def value(self, y: np.ndarray) -> float | None:
        """The barrier at ``y`` alone (a line search's); None outside the domain."""
        roots = self._roots(y)
        if roots is None:
            return None
        value = -2 * np.log(np.diagonal(roots[1], axis1=1, axis2=2)).sum()
        if len(self.rows):
            values = self.rows @ y
            if (values <= 0).any():
                return None
            value -= np.log(values).sum()
        return float(value) if np.isfinite(value) else None

    def __call__(self, y: np.ndarray) -> tuple[float, np.ndarray, np.ndarray] | None:
        """(the barrier, its gradient, its Hessian) at ``y``; None outside the domain."""
        roots = self._roots(y)
        if roots is None:
            return None
        j, root = roots
        try:
            inverse_basis = np.linalg.inv(j)[:, None] @ self.bases           # J^-1 B_j, (bodies, y, 4, 4)
        except np.linalg.LinAlgError:
            return None
        if not np.isfinite(inverse_basis).all():
            return None
        value = -2 * np.log(np.diagonal(root, axis1=1, axis2=2)).sum()
        gradient = -np.trace(inverse_basis, axis1=2, axis2=3).sum(axis=0)
        # tr(M_i M_j) = <M_i, M_j^T>, summed over the bodies: one product
        flat = inverse_basis.transpose(1, 0, 2, 3).reshape(len(y), -1)
        flat_t = inverse_basis.transpose(1, 0, 3, 2).reshape(len(y), -1)
        curvature = flat @ flat_t.T
        if len(self.rows):
            values = self.rows @ y
            if (values <= 0).any():
                return None
            value -= np.log(values).sum()
            gradient -= self.rows.T @ (1 / values)
            curvature += (self.rows.T / values**2) @ self.rows
        return float(value), gradient, curvature


def _barrier_method(barrier: _Barrier, whitened: _Whitened) -> np.ndarray:
    """The y minimising weight x cost + barrier, the weight grown by GROWTH until the duality gap
    (barrier.size / weight) is below GAP, from the prior (consistent)."""
    y = whitened.at_prior
    # the first weight balances the barrier and the cost (m / the prior's cost), but no less than
    # 1e-12 of the barrier's curvature: the Newton system stays solvable in floating point
    at_prior = barrier(y)
    if at_prior is None:  # the prior is consistent (checked by the caller): inside the domain
        raise InvalidInputError("the prior is not physically consistent", argument="prior")
    weight = max(barrier.size / max(whitened.cost(y), 1e-300), 1e-12 * np.abs(at_prior[2]).max())
    while True:
        y = _newton(barrier, whitened.cost, whitened.optimum, y, weight)
        if barrier.size / weight < GAP:
            return y
        weight *= GROWTH


def _newton(barrier: _Barrier, cost: Callable[[np.ndarray], float], optimum: np.ndarray, y: np.ndarray,
            weight: float) -> np.ndarray:
    """At most NEWTON_STEPS Newton steps on weight x cost + barrier from ``y``: damped by a
    backtracking line search that keeps y inside the domain while the decrement is at least
    QUADRATIC, full (halved only to stay inside) below it, until the decrement is below 1e-12
    or stops falling."""
    previous = np.inf
    for _ in range(NEWTON_STEPS):
        evaluated = barrier(y)
        if evaluated is None:  # the steps keep y inside; rounding alone could leave
            break
        value, gradient, curvature = evaluated
        g = weight * (y - optimum) + gradient
        system = weight * np.eye(len(y)) + curvature
        try:
            step = -np.linalg.solve(system, g)
        except np.linalg.LinAlgError:       # rounding, with a J near singular: least squares
            step = -np.linalg.lstsq(system, g, rcond=None)[0]
        if not np.isfinite(step).all():
            break
        decrement = -g @ step
        if decrement < 1e-12 or decrement >= previous:
            break
        alpha = 1.0
        if decrement < QUADRATIC:
            previous = decrement
            while alpha > 1e-12 and barrier.value(y + alpha * step) is None:
                alpha *= 0.5
        else:
            here = weight * cost(y) + value
            while alpha > 1e-12:
                trial = barrier.value(y + alpha * step)
                if trial is not None and weight * cost(y + alpha * step) + trial <= here - 0.25 * alpha * decrement:
                    break
                alpha *= 0.5
        if alpha <= 1e-12:
            break
        y = y + alpha * step
    return y
