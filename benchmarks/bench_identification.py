"""The figures of docs/identification.md, computed: `phantom-pin excite` with its defaults (wall
time, also as a ratio to one estimate() of a 20 s log in the same run; condition numbers, peak
torques), and the identification of simulated devices of known parameters: the bias of the
friction estimates over the cutoffs identify offers, and the held-out accuracy of the general
and the report-structure fits on a device NOT of the report's structure.

    python benchmarks/bench_identification.py

The device is tests/identification/structure/test_structures.py's (its numbers, not copied: imported).
"""

from __future__ import annotations

import os
import platform
import sys
import tempfile
import time
from contextlib import redirect_stdout
from io import StringIO
from pathlib import Path

import numpy as np

TESTS = Path(__file__).resolve().parents[1] / "tests"
sys.path[:0] = [str(TESTS / "identification" / "structure"), str(TESTS)]

from test_structures import COULOMB, DEVICE, NOISE, VISCOUS  # noqa: E402

from phantom_pin import Device, Phantom, describe  # noqa: E402
from phantom_pin.cli import main  # noqa: E402
from phantom_pin.config.sampling import sample_postures  # noqa: E402
from phantom_pin.identification import estimate, overlay  # noqa: E402
from phantom_pin.identification.data import io, simulation  # noqa: E402


def rms(error: np.ndarray, reference: np.ndarray) -> float:
    return float(np.sqrt((error**2).mean() / (reference**2).mean()))


def main_() -> None:
    print(f"{platform.machine()}, Python {platform.python_version()}, {os.cpu_count()} cores")
    folder = Path(tempfile.mkdtemp())
    printed = StringIO()
    start = time.perf_counter()
    with redirect_stdout(printed):
        assert main(["--quiet", "excite", "-o", str(folder / "traj.csv")]) == 0
    excite_seconds = time.perf_counter() - start
    print(f"phantom-pin excite (defaults): {excite_seconds:.1f} s")
    print("  " + "\n  ".join(printed.getvalue().splitlines()[1:3]))
    t, theta, dtheta, ddtheta, tau = io.read_trajectory(folder / "traj.csv")
    model = Phantom(describe())
    log = simulation.track(DEVICE, t, theta, dtheta, tau, torque_noise=NOISE, seed=1)
    start = time.perf_counter()
    fits = {cutoff: estimate(log, model, cutoff) for cutoff in (10.0, 20.0, 40.0)}
    one = (time.perf_counter() - start) / 3
    print(f"one estimate() of the 20 s log: {one:.2f} s; excite = {excite_seconds / one:.0f} estimates")
    print(f"\nfriction of the device (viscous {VISCOUS} N m s/rad, Coulomb {COULOMB} N m, {NOISE * 1e3:g} mN m noise, "
          "encoders), error per joint:")
    for cutoff, fit in fits.items():
        values = fit.friction[0]
        print(f"  cutoff {cutoff:4g} Hz: viscous " + ", ".join(f"{100 * (v / VISCOUS - 1):+.1f} %" for v in values[:3])
              + "; Coulomb " + ", ".join(f"{100 * (v / COULOMB - 1):+.1f} %" for v in values[3:]))
    print("\nheld-out torque error against the device:")
    with redirect_stdout(StringIO()):
        assert main(["--quiet", "excite", "-o", str(folder / "held.csv"), "--seed", "5", "--iterations", "5"]) == 0
    _, q, v, a, _ = io.read_trajectory(folder / "held.csv")
    rng = np.random.default_rng(17)
    states = sample_postures(model.config.limits, 500, rng, draws=2000)
    random = (states, rng.normal(0, 2, (500, 3)), rng.normal(0, 20, (500, 3)))
    truth_trajectory = DEVICE.phantom.inverse_dynamics(q, v, a) + DEVICE.friction(v)
    truth_random = DEVICE.phantom.inverse_dynamics(*random)
    for structure in ("general", "report"):
        fit = estimate(log, model, structure=structure)
        device = Device(Phantom(describe(overrides=overlay(fit)[0])))
        trajectory = rms(device.phantom.inverse_dynamics(q, v, a) + device.friction(v) - truth_trajectory,
                         truth_trajectory)
        states_error = rms(device.phantom.inverse_dynamics(*random) - truth_random, truth_random)
        print(f"  {structure:8}: held-out trajectory {100 * trajectory:.3f} %, random states "
              f"{100 * states_error:.3f} %; residual "
              + ", ".join(f"{100 * r / s:.2f} %" for r, s in zip(fit.rms, fit.torque_rms)))
    shipped = rms(model.inverse_dynamics(q, v, a) + model.config.actuation.friction.torque(v) - truth_trajectory,
                  truth_trajectory)
    print(f"  the report's parameters: held-out trajectory {100 * shipped:.2f} %")


if __name__ == "__main__":
    main_()
