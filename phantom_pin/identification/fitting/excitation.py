"""Excitation: a periodic finite Fourier series inside the real stops, optimised for the
condition number of the base regressor.

theta_i(t) = q0_i + sum_k a_ik/(k w) sin(k w t) - b_ik/(k w) cos(k w t), k = 1..H, w = 2 pi/T
(rad; rates rad/s, accelerations rad/s^2). The last harmonic's coefficients are set so that
the trajectory starts and ends each period at rest (dtheta = ddtheta = 0 at t = 0).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

import numpy as np

from phantom_pin import _blas
from phantom_pin.description.build import Description
from phantom_pin.dynamics.phantom import Phantom
from phantom_pin.exceptions import InvalidInputError
from phantom_pin.identification.fitting.least_squares import condition_number as condition_number  # (lived here)
from phantom_pin.identification.structure.structures import General, Report, friction_block

#: The rate (rad/s) below which the optimiser's Coulomb column is smoothed (its sign's jump
#: would stall SLSQP's finite differences); the result is checked with the law itself.
SMOOTH_SPEED = 0.05
#: A restart replaces the best one only where its cost (a log: relative in the condition number
#: and the sizes) is lower by more than this: within it, the earlier start is kept.
RESTART_TIE = 1e-9


@dataclasses.dataclass(frozen=True)
class Fourier:
    """A finite Fourier series: offsets q0 (3,) rad, coefficients a, b (3, H) rad/s, period (s)."""

    q0: np.ndarray
    a: np.ndarray
    b: np.ndarray
    period: float

    @classmethod
    def from_free(cls, free: np.ndarray, harmonics: int, period: float) -> Fourier:
        """From q0 and the first H-1 harmonics; the H-th makes dtheta(0) = ddtheta(0) = 0."""
        q0, rest = free[:3], free[3:].reshape(2, 3, harmonics - 1)
        k = np.arange(1, harmonics)
        a = np.hstack([rest[0], -rest[0].sum(axis=1, keepdims=True)])
        b = np.hstack([rest[1], -(rest[1] * k).sum(axis=1, keepdims=True) / harmonics])
        return cls(np.asarray(q0, float), a, b, float(period))

    def __call__(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(theta, dtheta, ddtheta), each (len(t), 3), at times t (s)."""
        w = 2 * np.pi / self.period
        k = np.arange(1, self.a.shape[1] + 1)
        phase = np.multiply.outer(np.asarray(t, float), k * w)          # (N, H)
        s, c = np.sin(phase), np.cos(phase)
        theta = self.q0 + (s / (k * w)) @ self.a.T - (c / (k * w)) @ self.b.T
        dtheta = c @ self.a.T + s @ self.b.T
        ddtheta = (-s * k * w) @ self.a.T + (c * k * w) @ self.b.T
        return theta, dtheta, ddtheta


def continuous_effort(description: Description) -> np.ndarray:
    """Each joint's torque limit, the URDF's effort (N m): the motor's max. continuous torque at
    its joint, or the configuration's joint_torque_limit without public motor data (the Touch).
    The excitation's torque bound."""
    return np.array(description.config.actuation.effort)


@dataclasses.dataclass(frozen=True)
class Excitation:
    trajectory: Fourier
    condition: float        # of the general base regressor over one period (columns scaled to unit norm)
    report_condition: float | None  # of the report structure's (None for a model in full)
    peak_torque: np.ndarray  # N m per joint, the configuration's model with its friction
    min_slack: float        # rad, nearest approach to a stop


def _check_arguments(**values: float) -> None:
    """optimise()'s numbers: InvalidInputError naming the first that is out of its range."""
    integers = {"harmonics": 2, "samples": 10, "restarts": 1, "iterations": 1, "seed": 0}
    for name, value in values.items():
        if name in integers:
            if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < integers[name]:
                raise InvalidInputError(f"expected an integer of at least {integers[name]}, got {value!r}",
                                        argument=name)
        elif isinstance(value, bool) or not isinstance(value, (int, float)) or not np.isfinite(value):
            raise InvalidInputError(f"expected a finite number, got {value!r}", argument=name)
    if values["period"] <= 0:
        raise InvalidInputError(f"expected a positive number (s), got {values['period']!r}", argument="period")
    for name in ("margin", "amplitude_weight"):
        if values[name] < 0:
            raise InvalidInputError(f"expected a number >= 0, got {values[name]!r}", argument=name)
    if not 0 < values["torque_share"] <= 1:
        raise InvalidInputError(f"expected a share in (0, 1], got {values['torque_share']!r}", argument="torque_share")


def optimise(phantom: Phantom, period: float = 5.0, harmonics: int = 5,
             samples: int = 150, margin: float = 0.05, torque_share: float = 0.8,
             restarts: int = 2, iterations: int = 60, seed: int = 0, times: np.ndarray | None = None,
             progress: Callable[[float], None] | None = None,
             amplitude_weight: float = 3.0) -> Excitation:
    """Minimise log(condition number) - amplitude_weight x mean log(singular value) of the
    general base regressor (structures.General: every identifiable combination of the rigid
    body in full and friction; columns scaled to unit norm for the first, weighted by each base
    parameter's typical size for the second, so that the torques grow against the noise) over
    the Fourier coefficients, subject to: positions ``margin`` (rad) inside every stop, and the
    configuration's model's torque (with its friction) below ``torque_share`` of each joint's
    torque limit. SLSQP from ``restarts`` seeded random starts; the best feasible result is
    returned.

    The optimiser samples a period at ``samples`` points; the result is then checked at
    ``times`` (s, the file's samples; default: the same points), stepping back towards the
    start until the stops' margin and the torque share hold there too, and its condition
    numbers, peak torque and nearest approach are those at ``times``. ``progress(share)`` is
    called with the share of the SLSQP iterations done. ``phantom``: the Phantom whose
    configuration is excited."""
    _check_arguments(period=period, harmonics=harmonics, samples=samples, margin=margin, torque_share=torque_share,
                     restarts=restarts, iterations=iterations, seed=seed, amplitude_weight=amplitude_weight)
    if progress is not None and not callable(progress):
        raise InvalidInputError(f"expected a callable (share) or None, got {progress!r}", argument="progress")
    if times is not None:
        times = np.asarray(times, dtype=float)
        if times.ndim != 1 or not len(times) or not np.isfinite(times).all():
            raise InvalidInputError("expected a non-empty 1-D array of finite times (s)", argument="times")
    if not isinstance(phantom, Phantom):
        raise InvalidInputError(f"expected a phantom_pin.Phantom (Phantom(description) for a Description), got a "
                                f"{type(phantom).__name__}", argument="phantom")
    problem = _Problem(phantom, period, harmonics, samples, margin, torque_share, amplitude_weight, times)
    # on one BLAS kernel and one thread: SLSQP's path hinges on the last bits (phantom_pin._blas)
    return _blas.run(_optimised, problem, restarts, iterations, seed, progress=progress)


def _optimised(problem: _Problem, restarts: int, iterations: int, seed: int,
               progress: Callable[[float], None] | None) -> Excitation:
    """optimise's result on ``problem`` (its search, then the checks at ``problem.checked``)."""
    best = _search(problem, restarts, iterations, seed, progress)
    trajectory = Fourier.from_free(best, problem.harmonics, problem.period)
    states, phi, torque = problem.evaluate(best, problem.checked, exact=True)
    report = None
    if problem.general.phantom.description.config.report is not None:
        report = condition_number(Report(problem.general.phantom).regressor_of(*states)[0].reshape(-1, 14))
    return Excitation(trajectory, condition_number(phi), report, np.abs(torque).max(axis=0),
                      float(problem.limits.slack(states[0]).min()))


class _Problem:
    """optimise's problem over the Fourier coefficients ``free``: the cost (conditioning and
    amplitude of the general base regressor), the inequalities (stops' margin, torque share) at the
    optimiser's ``samples`` points ``t``, and feasibility at the ``checked`` times too."""

    def __init__(self, phantom: Phantom, period: float, harmonics: int, samples: int, margin: float,
                 torque_share: float, amplitude_weight: float, times: np.ndarray | None) -> None:
        description = phantom.description
        self._arguments = (description, period, harmonics, samples, margin, torque_share, amplitude_weight, times)
        self.period, self.harmonics, self.margin = period, harmonics, margin
        self.torque_share, self.amplitude_weight = torque_share, amplitude_weight
        self.limits = description.config.limits
        self.effort = continuous_effort(description)
        self.general = General(phantom)
        self.beta = self.general.matrix @ self.general.prior                # the configuration's own base parameters
        self.typical = np.abs(self.general.matrix) @ self.general.scale     # each base parameter's typical size
        self.t = np.linspace(0.0, period, samples, endpoint=False)
        self.checked = self.t if times is None else np.unique(np.mod(np.asarray(times, float), period))
        self._memo: dict[bytes, tuple] = {}

    def __reduce__(self) -> tuple:
        """Pickled as its arguments (a child process on the reference BLAS builds it again)."""
        return (_problem, self._arguments)

    def evaluate(self, free: np.ndarray, at: np.ndarray | None = None, exact: bool = False) -> tuple:
        """(states, Phi stacked (3N, P), torque (N, 3)) at the times ``at`` (default ``t``): for the
        optimiser with the Coulomb column smoothed (tanh(dtheta / SMOOTH_SPEED): the cost and the
        constraints stay differentiable for SLSQP), ``exact`` with the friction law itself."""
        at = self.t if at is None else at
        key = free.tobytes() + (b"exact" if exact else b"") + (b"" if at is self.t else b"checked")
        if key in self._memo:
            self._memo[key] = self._memo.pop(key)            # the newest: kept longest
        else:
            # SLSQP's finite differences of the cost and then of the constraints step to the same
            # points: keep one gradient's worth of evaluations (the oldest dropped first)
            while len(self._memo) > 2 * len(free) + 4:
                del self._memo[next(iter(self._memo))]
            states = Fourier.from_free(free, self.harmonics, self.period)(at)
            rates = states[1]
            smooth = None if exact else friction_block(np.concatenate([rates, np.tanh(rates / SMOOTH_SPEED)], axis=-1))
            phi, tau0 = self.general.regressor_of(*states, smooth)
            self._memo[key] = states, phi.reshape(-1, len(self.beta)), phi @ self.beta + tau0
        return self._memo[key]

    def cost(self, free: np.ndarray) -> float:
        phi = self.evaluate(free)[1]
        # condition number, and (D-optimality) the mean log singular value of the regressor with
        # columns weighted by the typical sizes: rewards torque signals large against the noise.
        # Both from the eigenvalues of the small Gram matrix (the squared singular values), or
        # from singular values where squaring would lose them (a poorly exciting start)
        gram = phi.T @ phi
        norms = np.sqrt(np.diag(gram))
        unit = np.linalg.eigvalsh(gram / np.outer(norms, norms))
        typical, weight = self.typical, self.amplitude_weight
        if unit[0] > 1e-10 * unit[-1]:
            weighted = np.linalg.eigvalsh(gram * np.outer(typical, typical) / len(phi))
            if weighted[0] > 0:   # else rounding took the smallest below zero: the singular values below
                return 0.5 * np.log(unit[-1] / unit[0]) - weight * 0.5 * np.log(weighted).mean()
        size = np.linalg.svd(phi * typical / np.sqrt(len(phi)), compute_uv=False)
        return np.log(condition_number(phi)) - weight * np.log(size).mean()

    def inequalities(self, free: np.ndarray) -> np.ndarray:
        states, _, torque = self.evaluate(free)
        return np.concatenate([self.limits.slack(states[0]).ravel() - self.margin,
                               (self.torque_share * self.effort - np.abs(torque)).ravel() * 10])

    def feasible(self, free: np.ndarray) -> bool:
        """The inequalities at the optimiser's points and at ``checked``."""
        if self.inequalities(free).min() < -1e-9:
            return False
        states, _, torque = self.evaluate(free, self.checked, exact=True)
        return bool(self.limits.slack(states[0]).min() >= self.margin - 1e-9
                    and (self.torque_share * self.effort - np.abs(torque)).min() >= -1e-12)


def _problem(description: Description, *arguments: object) -> _Problem:
    return _Problem(Phantom(description), *arguments)  # type: ignore[arg-type]


def _search(problem: _Problem, restarts: int, iterations: int, seed: int,
            progress: Callable[[float], None] | None) -> np.ndarray:
    """The best feasible coefficients of SLSQP from ``restarts`` seeded random starts, each result
    stepped back towards its start until feasible; InvalidInputError naming ``restarts`` if none is."""
    import scipy.optimize  # here: 0.2-0.3 s that every command line start paid (the package imports this module)

    rng = np.random.default_rng(seed)
    start_q0 = np.array([0.0, 0.35, 0.35])
    best, best_cost = None, np.inf
    done = [0]

    def step(_):
        done[0] += 1
        if progress is not None:
            progress(done[0] / (iterations * restarts))

    for restart in range(restarts):
        free0 = np.concatenate([start_q0, rng.normal(0, 0.05, 2 * 3 * (problem.harmonics - 1))])
        result = scipy.optimize.minimize(problem.cost, free0, method="SLSQP", callback=step,
                                         constraints=[{"type": "ineq", "fun": problem.inequalities}],
                                         options={"maxiter": iterations, "ftol": 1e-6})
        done[0] = (restart + 1) * iterations
        # an unfinished run, or the points between the optimiser's, may leave the limits:
        # step back towards the (small) start
        for alpha in (1.0, 0.95, 0.9, 0.8, 0.6, 0.4, 0.2, 0.0):
            candidate = free0 + alpha * (result.x - free0)
            if problem.feasible(candidate):
                if problem.cost(candidate) < best_cost - RESTART_TIE:     # the earliest start of a tie
                    best, best_cost = candidate, problem.cost(candidate)
                break
    if best is None:
        raise InvalidInputError(f"no feasible trajectory found in {restarts} start(s); raise restarts "
                                "(--restarts) or lower margin", argument="restarts")
    return best
