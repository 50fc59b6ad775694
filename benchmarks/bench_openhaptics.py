"""The cost of compensating in OpenHaptics' servo tick: the Python Compensator (one call per tick
of a pyOpenHaptics callback: the tick's joint and gimbal angles to HD_CURRENT_FORCE) and the
generated header's NAME_openhaptics_force (C, gcc -O2), each as the median of rounds of many
calls on seeded states, against a reference call in the same run (Phantom.gravity alone: the
Python API's one-state gravity), so that the ratio survives a slower or busier machine; and
one tick of the libHD stand-in's simulated device (plant.Server.tick, Python).

    python benchmarks/bench_openhaptics.py [--model touch] [--rounds 15]

The issue's budget is 50 us per compensator call; docs/servo-loop.md quotes this script.
"""

from __future__ import annotations

import argparse
import ctypes
import os
import platform
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np

from phantom_pin import Phantom
from phantom_pin.codegen import header
from phantom_pin.config import read
from phantom_pin.config.sampling import random_states
from phantom_pin.interfaces.openhaptics import Compensator
from phantom_pin.interfaces.openhaptics.plant import Server

CALLS = 2000
SHIM = """#include "model.h"
#include <time.h>
double bench(int n, const double *a, const double *g) {
    struct timespec t0, t1; double f[3], sink = 0; int k;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    for (k = 0; k < n; ++k) { phantom_openhaptics_force(a + 3 * (k % 64), g + 3 * (k % 64), f); sink += f[0]; }
    clock_gettime(CLOCK_MONOTONIC, &t1);
    return ((t1.tv_sec - t0.tv_sec) + 1e-9 * (t1.tv_nsec - t0.tv_nsec)) / n + 0 * sink;
}
"""


def per_call(function, states, gimbals, rounds):
    """The median over ``rounds`` of the mean time (s) of CALLS calls."""
    times = []
    for _ in range(rounds):
        start = time.perf_counter()
        for k in range(CALLS):
            function(states[k % len(states)], gimbals[k % len(gimbals)])
        times.append((time.perf_counter() - start) / CALLS)
    return statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model", default="touch")
    parser.add_argument("--rounds", type=int, default=15)
    args = parser.parse_args()
    config = read(args.model)
    theta = random_states(config.limits, 64, seed=7)[0]
    angles = theta * np.array([-1.0, 1.0, 1.0])
    gimbal = np.zeros((64, 3)) if config.gimbal is None else \
        np.random.default_rng(8).uniform(config.gimbal.lower, config.gimbal.upper, (64, 3))
    phantom = Phantom.from_model(args.model)
    compensate = Compensator(args.model)
    stylus = config.gimbal is not None
    reference = per_call(lambda t, g: phantom.gravity(t), list(theta), list(gimbal), args.rounds)
    python = per_call(lambda a, g: compensate(a, g if stylus else None), [list(a) for a in angles],
                      [list(g) for g in gimbal], args.rounds)
    transparent = Compensator(args.model, compensate=("gravity", "friction", "inertia"), kappa=0.6)
    moving = per_call(lambda a, g: transparent(a, g if stylus else None), [list(a) for a in angles],
                      [list(g) for g in gimbal], args.rounds)
    with tempfile.TemporaryDirectory() as scratch:
        folder = Path(scratch)
        (folder / "model.h").write_text(header(args.model))
        (folder / "shim.c").write_text(SHIM)
        subprocess.run(["gcc", "-std=gnu99", "-O2", "-fPIC", "-shared", "shim.c", "-o", "libshim.so", "-lm"],
                       cwd=folder, check=True)
        library = ctypes.CDLL(str(folder / "libshim.so"))
        library.bench.restype = ctypes.c_double
        pointer = ctypes.POINTER(ctypes.c_double)
        a, g = (np.ascontiguousarray(x) for x in (angles, gimbal))
        c = statistics.median(library.bench(ctypes.c_int(200000), a.ctypes.data_as(pointer), g.ctypes.data_as(pointer))
                              for _ in range(args.rounds))
    os.environ["PHANTOM_PIN_HD_MODEL"] = args.model
    os.environ["PHANTOM_PIN_HD_THETA0"] = " ".join(repr(float(v)) for v in theta[0])
    server = Server()
    command = (1.0, *([0.0] * 6), 1e-3, 0.0, 0.0, 0.0)
    ticks = []
    for _ in range(args.rounds):
        start = time.perf_counter()
        for _ in range(500):
            server.tick(command)
        ticks.append((time.perf_counter() - start) / 500)
    tick = statistics.median(ticks)
    print(f"# {args.model}, {platform.python_implementation()} {platform.python_version()}, {os.cpu_count()} cores; "
          f"medians of {args.rounds} rounds")
    print("| call | time | / Phantom.gravity |")
    print("|---|---|---|")
    print(f"| Phantom.gravity (reference) | {reference * 1e6:.1f} us | 1.00 |")
    print(f"| Compensator (pyOpenHaptics' call a tick) | {python * 1e6:.1f} us | {python / reference:.2f} |")
    print(f"| Compensator, gravity, friction and inertia (the arm moving) | {moving * 1e6:.1f} us | "
          f"{moving / reference:.2f} |")
    print(f"| header NAME_openhaptics_force (C, -O2) | {c * 1e9:.1f} ns | {c / reference:.4f} |")
    print(f"| stand-in device tick (plant.Server.tick) | {tick * 1e6:.1f} us | {tick / reference:.2f} |")


if __name__ == "__main__":
    main()
