"""docs/feel.md's tables (issue 52, item 1): what the hand feels at the nominal posture of each
model (phantom_pin.device.feel), with the workspace volume checked by a quasi-Monte-Carlo count.

    python benchmarks/feel_figures.py [-o FILE [--force]]

Prints Markdown (or writes it to FILE): one table of the measures per model at the SRDF's zero
posture (theta = 0, the spec sheets' nominal orthogonal-arms position), then the workspace table
with the volume as the integral of |det J| over the stops and as the share of 2^16 scrambled
Sobol points of the box (seed 52) that the closed-form inverse kinematics reaches inside the stops
(Device.reachable). Deterministic; about 4 s of CPU here (the counts most of it).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
from scipy.stats import qmc

from phantom_pin import Device, feel, models

SOBOL_POWER = 16


def _row(name: str, values: object, spec: str = "{:.2f}") -> str:
    return f"| {name} | " + " | ".join(spec.format(v) for v in np.asarray(values).ravel()) + " |"


def measures_table() -> str:
    """The measures at theta = 0, one column per model."""
    devices = {name: Device.from_model(name) for name in models()}
    feels = {name: feel(device) for name, device in devices.items()}
    lines = ["| at theta = 0 (frame s: x right, y up, z towards the user) | " + " | ".join(feels) + " |",
             "|---|" + "---|" * len(feels)]

    def row(label: str, values: list[str]) -> None:
        lines.append(f"| {label} | " + " | ".join(values) + " |")

    each = feels.values()
    row("apparent mass along x, y, z (g), 1 / (u^T Λ^-1 u)", [" / ".join(f"{v:.1f}" for v in m.axis_masses)
                                                            for m in each])
    row("principal apparent masses (g), eigenvalues of Λ", [" / ".join(f"{v:.1f}" for v in m.principal_masses)
                                                          for m in each])
    row("breakaway backdrive force along x, y, z (N)", [" / ".join(f"{v:.3f}" for v in m.breakaway_along)
                                                      for m in each])
    row("sliding backdrive force at 0.1 m/s along x, y, z (N)", [" / ".join(f"{v:.3f}" for v in m.sliding_along)
                                                               for m in each])
    row("peak tip force +x / -x / +y / -y / +z / -z (N)", [" / ".join(f"{v:.2f}" for v in m.peak_force)
                                                          for m in each])
    row("least peak tip force over ±x, ±y, ±z (N)", [f"{m.peak_force.min():.2f}" for m in each])
    row("continuous tip force +x / -x / +y / -y / +z / -z (N)", [" / ".join(f"{v:.2f}" for v in m.continuous_force)
                                                                for m in each])
    row("least continuous tip force over ±x, ±y, ±z (N)", [f"{m.continuous_force.min():.2f}" for m in each])
    row("HD_NOMINAL_MAX_FORCE (actuation.yaml, N)", [f"{m.nominal_max_force:g}" for m in each])
    return "\n".join(lines)


def workspace_table() -> str:
    """The box and the volume, with its quasi-Monte-Carlo check."""
    lines = ["| model | x (mm) | y (mm) | z (mm) | volume, ∫ abs(det J) (cm^3) | volume, Sobol count (cm^3) |",
             "|---|---|---|---|---|---|"]
    for name in models():
        device = Device.from_model(name)
        m = feel(device)
        lower, upper = m.box_lower / 1e3, m.box_upper / 1e3
        points = lower + (upper - lower) * qmc.Sobol(3, seed=52).random_base2(SOBOL_POWER)
        counted = np.prod(upper - lower) * device.reachable(points).mean() * 1e6
        box = [f"{lo:.1f} .. {hi:.1f}" for lo, hi in zip(m.box_lower, m.box_upper)]
        lines.append(f"| {name} | " + " | ".join(box) + f" | {m.volume:.0f} | {counted:.0f} |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("-o", "--output", type=Path, help="write the Markdown here instead of standard output")
    parser.add_argument("--force", action="store_true", help="overwrite --output")
    args = parser.parse_args(argv)
    if args.output is not None and args.output.exists() and not args.force:
        parser.error(f"{args.output} exists; give --force to overwrite it")
    text = measures_table() + "\n\n" + workspace_table() + "\n"
    if args.output is None:
        sys.stdout.write(text)
    else:
        args.output.write_text(text, encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
