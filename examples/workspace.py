"""The real workspace: tip positions (m, the report's frame s) over a grid of postures inside
the device's stops (the joint box and the parallelogram's coupled stops), plotted from the
side and from above, with the advertised 381 x 267 x 191 mm workspace box where it fits best.

Frame s (report): x left, y up, z forward, origin at the tip of the zero configuration.
The tips are checked against the closed form (eq. 10); the distances are from the shoulder,
which sits at (0, l2, -l1) in frame s. The coverage is the share of a grid over the advertised
box whose points Device.reachable finds reachable inside the stops; the box is centred on
axis 1 (x = 0) and slid in y and z.
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

import common
from phantom_pin import Device, PhantomPinError, closed_form

#: The Premium 1.5's advertised workspace, width (x) x height (y) x depth (z), m.
ADVERTISED = np.array([0.381, 0.267, 0.191])


def best_placement(device: Device, tips: np.ndarray, steps: int) -> tuple[float, np.ndarray]:
    """The largest reachable share of a grid over the advertised box, and the box centre (m,
    frame s), over ``steps`` x ``steps`` centres spanning the tips' y and z ranges."""
    unit = np.stack(np.meshgrid(*(np.linspace(-0.5, 0.5, n) for n in (15, 11, 9)), indexing="ij"), -1)
    grid = unit.reshape(-1, 3) * ADVERTISED
    best = (-1.0, np.zeros(3))
    for y in np.linspace(tips[:, 1].min(), tips[:, 1].max(), steps):
        for z in np.linspace(tips[:, 2].min(), tips[:, 2].max(), steps):
            centre = np.array([0.0, y, z])
            share = float(device.reachable(grid + centre).mean())
            if share > best[0]:
                best = (share, centre)
    return best


def main(argv: list[str] | None = None) -> None:
    cli = common.parser(__doc__.splitlines()[0])
    cli.add_argument("--samples", type=int, default=25, help="grid points per joint")
    cli.add_argument("--placements", type=int, default=15,
                     help="box centres tried along y and along z (default 15)")
    args = cli.parse_args(argv)
    if args.samples < 2:
        raise PhantomPinError("--samples: expected at least 2 grid points per joint")
    if args.placements < 1:
        raise PhantomPinError("--placements: expected at least 1")
    figure_path = common.output(args, "workspace.png")
    device = Device()
    limits, p = device.config.limits, device.config.kinematics     # the URDF's joint box; l1, l2
    axes_ = [np.linspace(lo, hi, args.samples) for lo, hi in zip(limits.lower, limits.upper)]
    box = np.stack(np.meshgrid(*axes_, indexing="ij"), axis=-1).reshape(-1, 3)
    theta = box[device.within_limits(box)]
    tip = device.phantom.forward_kinematics(theta)[:, :3, 3]                # (N, 3) m in frame s
    radius = np.linalg.norm(tip - np.array([0.0, p.l2, -p.l1]), axis=1)
    difference = np.abs(tip - closed_form.forward_kinematics(theta, p)[:, :3, 3]).max()
    share, centre = best_placement(device, tip, args.placements)
    low = centre - ADVERTISED / 2
    figure, (side, top) = plt.subplots(1, 2, figsize=(11, 5), constrained_layout=True)
    side.scatter(tip[:, 2], tip[:, 1], s=1, c=theta[:, 1], cmap="viridis")
    side.add_patch(plt.Rectangle((low[2], low[1]), ADVERTISED[2], ADVERTISED[1], fill=False, color="red"))
    side.set(xlabel="z forward [m]", ylabel="y up [m]", title="side view (colour: theta2)", aspect="equal")
    top.scatter(tip[:, 0], tip[:, 2], s=1, c=theta[:, 0], cmap="viridis")
    top.add_patch(plt.Rectangle((low[0], low[2]), ADVERTISED[0], ADVERTISED[2], fill=False, color="red"))
    top.set(xlabel="x left [m]", ylabel="z forward [m]", title="top view (colour: theta1)", aspect="equal")
    top.invert_xaxis()  # seen from above: the left (+x) is on the left
    figure.suptitle(f"inside the stops; red: the advertised box, {100 * share:.1f} % reachable")
    figure.savefig(figure_path, dpi=120)
    print(f"wrote {figure_path}")
    print(f"{len(theta)} of {len(box)} grid postures inside the stops; tip bounding box in frame s [m]: "
          f"x {tip[:, 0].min():+.4f}..{tip[:, 0].max():+.4f}, y {tip[:, 1].min():+.4f}..{tip[:, 1].max():+.4f}, "
          f"z {tip[:, 2].min():+.4f}..{tip[:, 2].max():+.4f}")
    print(f"distance from the shoulder {radius.min():.4f}..{radius.max():.4f} m")
    print(f"Phantom vs the closed form (eq. 10) over the grid: max difference {difference:.1e} m")
    print(f"advertised workspace {ADVERTISED * 1000} mm centred at {np.round(centre, 4)} m: "
          f"{100 * share:.1f} % reachable inside the stops")


if __name__ == "__main__":
    common.run(main)
