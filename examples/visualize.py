"""The arm in meshcat: a 4 s sweep across the real stops with a 1 N downward force
on the tip, written as a self-contained HTML file (open it in any browser), or served
live on 127.0.0.1 with --serve until Ctrl-C.
"""

from __future__ import annotations

import dataclasses

import numpy as np

import common
from phantom_pin import config, load
from phantom_pin.viewer import Viewer


def sweep(lower: np.ndarray, upper: np.ndarray, coupled: tuple[float, float],
          duration: float = 4.0) -> tuple[np.ndarray, np.ndarray]:
    """Times (s) and postures (rad) inside the joint box ``lower``..``upper`` and the
    coupled stops ``coupled`` = (max theta2 - theta3, max theta3 - theta2): joints 1 and 2
    swing smoothly across 10%..90% of their ranges once, and theta3 - theta2 across
    10%..90% of its coupled range twice (theta3 then clipped to its box)."""
    t = np.linspace(0.0, duration, 121)
    swing = 0.1 + 0.8 * (1 - np.cos(2 * np.pi * t[:, None] / duration * np.array([1.0, 1.0, 2.0]))) / 2
    theta = lower + (upper - lower) * swing
    forward, backward = coupled
    theta[:, 2] = np.clip(theta[:, 1] - forward + (forward + backward) * swing[:, 2], lower[2], upper[2])
    return t, theta


def main(argv: list[str] | None = None) -> None:
    cli = common.parser(__doc__.splitlines()[0])
    cli.add_argument("--serve", action="store_true", help="serve the viewer live until Ctrl-C")
    args = cli.parse_args(argv)
    html_path = None if args.serve else common.output(args, "visualize.html")
    robot = load()
    with Viewer(robot) as viewer:
        viewer.set_force([0.0, -1.0, 0.0])          # N, frame s: y is up
        viewer.animate(*sweep(robot.model.lowerPositionLimit, robot.model.upperPositionLimit,
                              dataclasses.astuple(config.read().limits.stops.coupled)),
                       repetitions=1000)
        if html_path is not None:
            print(f"wrote {viewer.export_html(html_path, force=args.force)}")
            return
        print(f"meshcat viewer at {viewer.url} (Ctrl-C to stop)", flush=True)
        viewer.wait()


if __name__ == "__main__":
    common.run(main)
