"""The reachable workspace: tip positions (m, the report's frame s) over a grid of
postures inside the joint limits, plotted from the side and from above.

Frame s (report): x left, y up, z forward, origin at the tip of the zero configuration.
The tips are checked against the closed form (eq. 10); the distances are from the
shoulder, which sits at (0, l2, -l1) in frame s.
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

import common
from phantom_pin import Phantom, PhantomPinError, closed_form


def main(argv: list[str] | None = None) -> None:
    cli = common.parser(__doc__.splitlines()[0])
    cli.add_argument("--samples", type=int, default=25, help="grid points per joint")
    args = cli.parse_args(argv)
    if args.samples < 2:
        raise PhantomPinError("--samples: expected at least 2 grid points per joint")
    figure_path = common.output(args, "workspace.png")
    phantom = Phantom()
    p = phantom.parameters
    axes_ = [np.linspace(lo, hi, args.samples) for lo, hi in zip(p.lower, p.upper)]
    theta = np.stack(np.meshgrid(*axes_, indexing="ij"), axis=-1).reshape(-1, 3)
    tip = phantom.forward_kinematics(theta)[:, :3, 3]                # (N, 3) m in frame s
    radius = np.linalg.norm(tip - np.array([0.0, p.l2, -p.l1]), axis=1)
    difference = np.abs(tip - closed_form.forward_kinematics(theta, p)[:, :3, 3]).max()
    figure, (side, top) = plt.subplots(1, 2, figsize=(11, 5), constrained_layout=True)
    side.scatter(tip[:, 2], tip[:, 1], s=1, c=theta[:, 1], cmap="viridis")
    side.set(xlabel="z forward [m]", ylabel="y up [m]", title="side view (colour: theta2)", aspect="equal")
    top.scatter(tip[:, 0], tip[:, 2], s=1, c=theta[:, 0], cmap="viridis")
    top.set(xlabel="x left [m]", ylabel="z forward [m]", title="top view (colour: theta1)", aspect="equal")
    top.invert_xaxis()  # seen from above: the left (+x) is on the left
    figure.savefig(figure_path, dpi=120)
    low, high = tip.min(axis=0), tip.max(axis=0)
    print(f"wrote {figure_path}")
    print(f"{len(theta)} postures; tip bounding box in frame s [m]: "
          f"x {low[0]:+.4f}..{high[0]:+.4f}, y {low[1]:+.4f}..{high[1]:+.4f}, z {low[2]:+.4f}..{high[2]:+.4f}")
    print(f"distance from the shoulder {radius.min():.4f}..{radius.max():.4f} m")
    print(f"Phantom vs the closed form (eq. 10) over the grid: max difference {difference:.1e} m")


if __name__ == "__main__":
    common.run(main)
