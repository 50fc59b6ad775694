"""phantom_pin.simulate against the MuJoCo loop (phantom_pin.device.mujoco_plant) with the same
Python controller at 1 kHz, friction and stops on: wall time per simulated second of each, and
their ratio, measured in the same run (interleaved rounds, medians).

    python benchmarks/bench_plants.py [--rounds 3]
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import time

import numpy as np

from phantom_pin import Device, Phantom, describe, simulate
from phantom_pin.device.mujoco_plant import simulate_mujoco

DEVICE = Device(Phantom(describe()))
GRAVITY = DEVICE.phantom.gravity
START = np.array([0.0, 0.3, 0.4])
DURATION = 2.0


def wall_controller():
    """examples/virtual_wall.py's 1000 N/m wall under a 1 N push (tests/device/test_mujoco_plant.py)."""
    phantom, normal = DEVICE.phantom, np.array([0.0, 1.0, 0.0])
    surface = phantom.forward_kinematics(START)[:3, 3]

    def controller(t, theta, dtheta):
        pose = phantom.forward_kinematics(theta)
        depth = (surface - pose[:3, 3]) @ normal
        force = (1000.0 * depth if depth > 0 else 0.0) - 1.0
        return GRAVITY(theta) + (pose[:3, :3] @ phantom.body_jacobian(theta)[:3]).T @ (force * normal)
    return phantom.inverse_kinematics(surface - 2e-3 * normal), controller


SCENARIOS = {
    "driven (gravity compensation + 0.05 N m sines)":
        (START, lambda t, q, v: GRAVITY(q) + 0.05 * np.sin(3 * t + np.array([0.0, 1.0, 2.0]))),
    "PD hold with gravity compensation": (START, lambda t, q, v: GRAVITY(q) + 0.5 * (START + 0.01 - q) - 0.01 * v),
    "free fall onto the stops": (START, None),
    "1000 N/m wall": wall_controller(),
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()
    if args.rounds < 1:
        parser.error(f"--rounds: expected an integer >= 1, got {args.rounds}")
    print(f"{platform.machine()}, Python {platform.python_version()}, {os.cpu_count()} cores; "
          f"{DURATION:g} s simulated per run, median of {args.rounds} rounds")
    print(f"{'scenario':50} {'simulate':>10} {'MuJoCo':>10} {'ratio':>7}   (s of wall time per simulated s)")
    for name, (theta0, controller) in SCENARIOS.items():
        times: dict[str, list[float]] = {"simulate": [], "mujoco": []}
        for _ in range(args.rounds):
            for key, run in (("simulate", simulate), ("mujoco", simulate_mujoco)):
                start = time.perf_counter()
                run(theta0, DURATION, controller, device=DEVICE)
                times[key].append((time.perf_counter() - start) / DURATION)
        ours, theirs = statistics.median(times["simulate"]), statistics.median(times["mujoco"])
        print(f"{name:50} {ours:10.4f} {theirs:10.4f} {ours / theirs:7.2f}")


if __name__ == "__main__":
    main()
