"""Closed-loop noise: the instrumental-variable estimate (IDIM-IV, Janot, Vandanjon and Gautier).

In a servo loop the torque noise the log does not see (an amplifier's current noise) moves the
joints it drives: it is in the accelerations, rates and angles the regressor Phi is computed
from, so Phi is correlated with the equations' noise and least squares is biased. Measured on a
lab's 60 s sum of sines with 10 mA of current noise (benchmarks/identification_figures.py, CAD
device, five seeds, delay and gains fixed): the mean of the seeds' written models 1.2 / 1.7 /
1.2 % off per joint against a spread of 2.1 / 0.6 / 0.5 % (joints 2 and 3 biased); the delay
estimated from the residual ran to -4 ms (the feedback's reaction to the noise-driven motion
fits a shifted torque) and viscous friction to +66 %.

The instruments are the regressor Z at a noise-free motion: the reference the loop tracked
(``reference``: its angles at the log's times, filtered and differentiated as the log's), which
no noise of the log moves, and which stays close to the measured motion (a tracking error of
milliradians against a motion of tenths of a radian). Two-stage least squares: the regressor
is replaced by its projection on the instruments, Phi_hat = Z (Z^T Z)^-1 Z^T Phi (one
projection over the stacked equations fitted), while the residuals, the joints' weights and the
noise's variance are measured with Phi itself (least_squares.fit's ``measured``); the prior and
the gains go through unchanged (the gains' columns are then the instruments' torques).

The delay: the residual criterion (timing.py) is biased in the loop, so the delay is estimated
as one more parameter of the instrumented fit: y(d) = Phi beta + (d - d_0) dtau/dt + e about the
current d (y(d) the torques read d after their positions), the rate of the filtered torques
dtau/dt instrumented by the rate of the instruments' predicted torque (Phi_hat beta + tau_0),
over DELAY_STEPS Gauss-Newton steps from zero, kept within timing.DELAY_BRACKET.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from phantom_pin.exceptions import InvalidInputError, LogError
from phantom_pin.identification.data.io import Log
from phantom_pin.identification.data.timing import DELAY_BRACKET, lagged
from phantom_pin.identification.fitting.filtering import Samples, filtered
from phantom_pin.identification.fitting.least_squares import fit
from phantom_pin.identification.structure.structures import Structure

__all__ = ["Instruments", "instrumented_delay", "instruments", "reference_angles"]

#: The log follows the reference (a closed loop on it) where each joint's tracking error RMS
#: stays below this share of the reference's motion (its standard deviation) on that joint.
TRACKING_SHARE = 0.1
#: Gauss-Newton steps of the instrumented delay estimate (each: one fit), and the change (s)
#: that ends them early.
DELAY_STEPS, DELAY_TOLERANCE = 4, 1e-6
#: The delay parameter's prior standard deviation (s): wide against the bracket (only keeps the
#: step's system regular).
DELAY_SPREAD = 0.1


@dataclasses.dataclass(frozen=True)
class Instruments:
    """The instruments of a closed-loop log: ``z`` (N, 3, P), the regressor at the reference's
    motion at the log's kept samples (every equation, fitted or not); ``tracking`` (3,) rad, the
    RMS of the log's angles less the reference's; ``motion`` (3,) rad, the reference's standard
    deviation per joint."""

    z: np.ndarray
    tracking: np.ndarray
    motion: np.ndarray

    def projected(self, phi: np.ndarray, moving: np.ndarray, extra: np.ndarray | None = None) -> np.ndarray:
        """``phi`` (N, 3, K) projected on the instruments (with ``extra`` (N, 3, L) instruments
        added) over the equations ``moving`` (N, 3): Phi_hat (N, 3, K), 0 outside them."""
        z = self.z if extra is None else np.concatenate([self.z, extra], axis=-1)
        z = (z * moving[..., None]).reshape(-1, z.shape[-1])
        x = (phi * moving[..., None]).reshape(-1, phi.shape[-1])
        coefficients = np.linalg.lstsq(z, x, rcond=None)[0]
        return (z @ coefficients).reshape(phi.shape)

    def predicted(self, phi: np.ndarray, moving: np.ndarray, beta: np.ndarray) -> np.ndarray:
        """The instruments' prediction of ``phi @ beta`` (N, 3) at every equation, fitted or not:
        Z times the projection's coefficients (fitted over ``moving``) times ``beta``."""
        z = (self.z * moving[..., None]).reshape(-1, self.z.shape[-1])
        coefficients = np.linalg.lstsq(z, (phi * moving[..., None]).reshape(-1, phi.shape[-1]), rcond=None)[0]
        return self.z @ (coefficients @ beta)

    def words(self) -> str:
        """The printed line: the closed loop and its tracking."""
        tracking = ", ".join(f"{1e3 * e:.3g}" for e in self.tracking)
        return (f"closed loop: the log follows the reference given within {tracking} mrad RMS per joint; "
                "instrumental variables (the regressor at the reference's motion), the delay with them; "
                "the torque gains not estimated (instrumented, unmodelled friction biases them)")


def reference_angles(log: Log, reference: object) -> np.ndarray:
    """The reference's angles (rad) at the log's times: ``reference`` is (t, theta), times (s)
    from its own start, read from the log's start, and angles (M, 3) rad (excite's trajectory:
    io.read_trajectory's first two), interpolated linearly; it must span the log.
    InvalidInputError naming ``reference`` otherwise."""
    try:
        t, theta = (np.asarray(x, dtype=float) for x in reference)  # type: ignore[attr-defined]
    except (TypeError, ValueError):
        raise InvalidInputError(f"expected (t, theta): times (M,) s and angles (M, 3) rad, got {reference!r:.80}",
                                argument="reference") from None
    if t.ndim != 1 or len(t) < 2 or theta.shape != (len(t), 3):
        raise InvalidInputError(f"expected times (M,) and angles (M, 3) with M >= 2, got {t.shape} and "
                                f"{theta.shape}", argument="reference")
    if not (np.isfinite(t).all() and np.isfinite(theta).all()) or not (np.diff(t) > 0).all():
        raise InvalidInputError("expected finite angles at strictly increasing times", argument="reference")
    at = log.t - log.t[0] + t[0]
    if at[-1] > t[-1] + 1e-9:
        raise InvalidInputError(f"the reference lasts {t[-1] - t[0]:.6g} s, the log {at[-1] - t[0]:.6g} s: it must "
                                "span the log (read from the log's start)", argument="reference")
    return np.column_stack([np.interp(at, t, theta[:, j]) for j in range(3)])


def instruments(log: Log, angles: np.ndarray, structure: Structure, cutoff: float, samples: Samples,
                friction_law: object, timing: str) -> Instruments:
    """The instruments of ``log`` from the reference's ``angles`` at its times (N, 3; rad,
    reference_angles): filtered at ``cutoff`` (Hz) as the log's ``samples`` were (their kept
    samples), the friction columns of ``friction_law`` (config.Friction) at the reference's
    rates. LogError where the log does not follow the reference (TRACKING_SHARE)."""
    tracking = np.sqrt(((log.theta - angles) ** 2).mean(axis=0))
    motion = angles.std(axis=0)
    far = [j + 1 for j in range(3) if not tracking[j] <= TRACKING_SHARE * max(motion[j], 1e-12)]
    if far:
        raise LogError(f"the log does not follow the reference on joint(s) {', '.join(map(str, far))} (tracking "
                       f"error RMS {', '.join(f'{e:.3g}' for e in tracking)} rad against motions of "
                       f"{', '.join(f'{m:.3g}' for m in motion)} rad; at most {TRACKING_SHARE:g} of the motion): "
                       "not a closed loop on it; check the reference and its start", argument="reference")
    reference = filtered(Log(log.t, angles, log.tau), cutoff, friction_law, timing)  # type: ignore[arg-type]
    if len(reference.index) != len(samples.index) or (reference.index != samples.index).any():
        raise LogError("the reference's samples do not match the log's", argument="reference")
    z = structure.regressor_of(reference.theta, reference.dtheta, reference.ddtheta, reference.friction)[0]
    return Instruments(z, tracking, motion)


def instrumented_delay(found: Instruments, samples: Samples, phi: np.ndarray, phi_hat: np.ndarray,
                       tau0: np.ndarray, moving: np.ndarray, prior: tuple[np.ndarray, np.ndarray] | None,
                       hold: float, scale: np.ndarray) -> float:
    """The delay (s) of the torques (times ``scale`` per joint) behind their positions, estimated
    with the instruments (module doc): ``phi`` (N, 3, P) the regressor, ``phi_hat`` its
    projection, ``tau0`` (N, 3; N m) the known torques, ``moving`` the equations fitted, ``prior``
    (beta_0, P) or None, ``hold`` the timing's lag (samples, timing.HOLD)."""
    rate, index = samples.rate, samples.index
    rates = np.gradient(samples.filtered_tau * scale, 1.0 / rate, axis=0)    # N m/s at every logged sample
    seconds = index / rate
    if prior is not None:
        prior = (np.append(prior[0], 0.0), _block(prior[1], DELAY_SPREAD**2))
    delay = 0.0
    for _ in range(DELAY_STEPS):
        lag = hold / rate - delay
        y = (scale * lagged(samples.filtered_tau, rate, index, lag) - tau0) * moving
        beta = fit(phi_hat, y, moving, None if prior is None else (prior[0][:-1], prior[1][:-1, :-1]), phi)[0]
        predicted = found.predicted(phi, moving, beta) + tau0     # the instruments' torque (N, 3)
        instrument = np.gradient(predicted, seconds, axis=0)[..., None]
        column = lagged(rates, rate, index, lag)[..., None]
        system = np.concatenate([phi, column], axis=-1)
        system_hat = found.projected(system, moving, instrument)
        solution = fit(system_hat, y, moving, prior, system)[0]
        step = float(solution[-1])             # y(d) = Phi beta + (d - d_0) dtau/dt: d_0 = d - step
        delay = float(np.clip(delay - step, *DELAY_BRACKET))
        if abs(step) <= DELAY_TOLERANCE:
            break
    return delay


def _block(covariance: np.ndarray, variance: float) -> np.ndarray:
    """``covariance`` (P, P) with one more parameter of ``variance``, independent: (P + 1, P + 1)."""
    p = covariance.shape[0]
    out = np.zeros((p + 1, p + 1))
    out[:p, :p], out[p, p] = covariance, variance
    return out

