"""The torques' timing against the positions: how a log's torque relates to its sample (held or
sampled), and the delay between them, estimated from the log itself (docs/identification.md).

A log's torques are "held" commands, each applied from its sample to the next (a servo loop's
zero-order hold: half a sample late against the positions), or "sampled" values, the torque at
that instant (a torque sensor, or torques computed from the motion). A logging delay shifts
them further. The regressor does not depend on the delay, only the torques do; a wrong delay
leaves about (delay error) x dtau/dt in them, whose jerk-driven part no column of the regressor
holds, so the weighted residual of the least-squares fit (``criterion``) grows with the error
on either side and its minimum is the true delay (``estimate_delay``).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from phantom_pin.exceptions import InvalidInputError

#: How a log's torques relate to its times: "held" (the default) or "sampled" (module doc).
TIMINGS = ("held", "sampled")
#: The lag (in samples) of each timing's torque behind the positions it belongs to.
HOLD = {"held": 0.5, "sampled": 0.0}
#: The delays (s) the estimate searches: torques logged up to 5 ms before or after the
#: positions they belong to (a servo loop at 1 kHz logs within a few samples); found on a grid
#: of GRID_STEP s, then refined by a parabola through the grid's best three (sub-sample).
DELAY_BRACKET, GRID_STEP = (-5e-3, 5e-3), 2.5e-4
#: The delays (s) accepted when given: from the bracket's start to a tenth of a second (less
#: than the filter's edge cut, filtering.EDGE: the shifted torques stay inside the log).
DELAY_RANGE = (DELAY_BRACKET[0], 0.1)
#: An estimated delay below -LEAD (s: torques logged more than a 1 kHz loop's sample before the
#: positions they belong to) is not a logger's: it is what torque noise a servo loop feeds back
#: into the motion looks like to the residual (the loop's reaction to the noise-driven motion fits
#: a torque read early). Measured on the figures table's lab logs with 10 mA of current noise
#: (benchmarks/identification_figures.py): -4.15 ms (CAD device) and -1.54 ms (report-structured);
#: no other row of the table below -0.1 ms. In seconds, not samples: a driver's record at 200 Hz
#: has a 5 ms sample, the bracket's edge. A warning (result.lead_warning), which names --reference
#: and --delay (a logger known to lead).
LEAD = 1e-3
#: The timing given fits "markedly" worse than the other when its weighted residual (the sum
#: of the joints' squared residual shares) exceeds the other's by this share: then a warning.
TIMING_MARGIN = 0.05


def delay_argument(delay: object) -> float | None:
    """``delay`` (s) checked: None (estimate it) or a finite number in DELAY_RANGE;
    InvalidInputError naming ``delay`` otherwise."""
    if delay is None:
        return None
    if isinstance(delay, bool) or not isinstance(delay, (int, float, np.floating, np.integer)) \
            or not np.isfinite(delay) or not DELAY_RANGE[0] <= delay <= DELAY_RANGE[1]:
        raise InvalidInputError(f"expected seconds between {DELAY_RANGE[0]:g} and {DELAY_RANGE[1]:g} (the torques "
                                f"logged that long after their positions), or None to estimate it; got {delay!r}",
                                argument="delay")
    return float(delay)


def lagged(smooth: np.ndarray, rate: float, index: np.ndarray, lag: float) -> np.ndarray:
    """The filtered torques ``smooth`` (N, 3; N m, at ``rate`` Hz) read ``lag`` seconds before
    the samples ``index``, by linear interpolation (the torques are low-passed far below the
    rate: at a 20 Hz cutoff and 1 kHz, interpolation errs by 0.2 % of the cutoff's component)."""
    at = index - lag * rate
    low = np.clip(np.floor(at).astype(int), 0, len(smooth) - 2)
    share = np.clip(at - low, 0.0, 1.0)[:, None]
    return (1 - share) * smooth[low] + share * smooth[low + 1]


def criterion(phi: np.ndarray, moving: np.ndarray, torque_rms: np.ndarray) -> Callable[[np.ndarray], float]:
    """The weighted residual of a fit of torques y (N, 3; N m) on phi (N, 3, P) over the
    equations ``moving`` (N, 3): the sum over the joints of the residual's mean square over
    their torque's (torque_rms (3,), N m), after the least-squares fit with those fixed weights
    (a projection, factored once: the regressor does not depend on the lag)."""
    weight = 1.0 / np.maximum(torque_rms, 1e-300)
    mask = moving * weight
    counts = np.maximum(moving.sum(axis=0), 1)
    q = np.linalg.qr((phi * mask[..., None]).reshape(-1, phi.shape[-1]))[0]

    def weighted(y: np.ndarray) -> float:
        yw = (y * mask).reshape(-1)
        r = (yw - q @ (q.T @ yw)).reshape(y.shape)
        return float(((r**2).sum(axis=0) / counts).sum())
    return weighted


def estimate_delay(smooth: np.ndarray, rate: float, index: np.ndarray, tau0: np.ndarray,
                   weighted: Callable[[np.ndarray], float], hold: float) -> float:
    """The delay (s) in DELAY_BRACKET whose shifted torques less ``tau0`` (N, 3; N m, the known
    torques at the samples ``index``) minimise ``weighted`` (grid, then a parabola through the
    best three points); ``smooth`` the filtered torques at every sample (N m, at ``rate`` Hz),
    ``hold`` the timing's lag (samples, HOLD)."""
    grid = np.arange(DELAY_BRACKET[0], DELAY_BRACKET[1] + GRID_STEP / 2, GRID_STEP)
    values = np.array([weighted(lagged(smooth, rate, index, hold / rate - d) - tau0) for d in grid])
    k = int(np.clip(np.argmin(values), 1, len(grid) - 2))
    left, middle, right = values[k - 1:k + 2]
    curvature = left - 2 * middle + right
    step = 0.5 * (left - right) / curvature if curvature > 0 else 0.0
    return float(grid[k] + np.clip(step, -1.0, 1.0) * GRID_STEP)
