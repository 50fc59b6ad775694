"""Gravity compensation in motor currents: the winding currents (A) that hold the arm still,
over the real device's workspace, against the motors' continuous rating, and the tip force
the motors have left.

theta1 does not change gravity torques, so the maps span theta2 x theta3 at theta1 = 0,
restricted to the real stops (Device.within_limits: each joint's stop and the parallelogram's
coupled stops). Currents are Device.motor_currents(N(theta)), N the gravity torque (eqs
93-94): i = N / (ratio * torque_constant), positive in the joint's positive direction. The
third map is Device.tip_force_capacity: the largest force (N) the motors can still push
straight down (-y in frame s) at their continuous torque while holding gravity.
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

import common
from phantom_pin import Device, closed_form


def main(argv: list[str] | None = None) -> None:
    cli = common.parser(__doc__.splitlines()[0])
    cli.add_argument("--samples", type=int, default=81, help="grid points per joint (theta2, theta3)")
    args = cli.parse_args(argv)
    figure_path = common.output(args, "gravity_currents.png")
    device = Device()
    stops, motor = device.config.limits.stops, device.config.actuation.motor
    theta2 = np.linspace(stops.lower[1], stops.upper[1], args.samples)
    theta3 = np.linspace(stops.lower[2], stops.upper[2], args.samples)
    grid = np.stack(np.meshgrid(theta2, theta3, indexing="ij"), axis=-1)
    theta = np.concatenate([np.zeros(grid.shape[:2] + (1,)), grid], axis=-1).reshape(-1, 3)
    inside = device.within_limits(theta)
    theta = theta[inside]
    currents = device.motor_currents(device.phantom.gravity(theta))           # (N, 3) A
    check = np.abs(currents * device.ratios * motor.torque_constant
                   - closed_form.gravity(theta, device.config.report)).max()
    down = device.tip_force_capacity(theta, [0.0, -1.0, 0.0])                 # N

    figure, axes = plt.subplots(1, 3, figsize=(15, 4.5), constrained_layout=True)
    maps = [(currents[:, 1], "i2 holding current [A]"), (currents[:, 2], "i3 holding current [A]"),
            (down, "continuous tip force left, downwards [N]")]
    for axis, (values, title) in zip(axes, maps):
        image = np.full(inside.shape, np.nan)
        image[inside] = values
        scale = {"cmap": "viridis"} if "force" in title else \
            {"cmap": "coolwarm", "vmin": -np.abs(values).max(), "vmax": np.abs(values).max()}  # white at 0 A
        mesh = axis.pcolormesh(np.degrees(theta3), np.degrees(theta2), image.reshape(grid.shape[:2]),
                               shading="auto", **scale)
        axis.set(xlabel="theta3 [deg]", ylabel="theta2 [deg]", title=title,
                 xlim=np.degrees([theta[:, 2].min(), theta[:, 2].max()]),
                 ylim=np.degrees([theta[:, 1].min(), theta[:, 1].max()]))
        figure.colorbar(mesh, ax=axis)
    figure.suptitle(f"gravity compensation inside the real stops; continuous rating {motor.max_continuous_current:g} A")
    figure.savefig(figure_path, dpi=120)
    print(f"wrote {figure_path}")
    print(f"{len(theta)} of {inside.size} grid postures inside the stops")
    print(f"currents x ratio x torque_constant vs closed_form.gravity: max difference {check:.2e} N m")
    worst = np.abs(currents).max(axis=0)
    for joint in (1, 2):
        where = np.degrees(theta[np.argmax(np.abs(currents[:, joint]))])
        print(f"motor {joint + 1}: worst holding current {worst[joint]:.4f} A = "
              f"{100 * worst[joint] / motor.max_continuous_current:.1f}% of the continuous "
              f"{motor.max_continuous_current:g} A "
              f"(at theta2 {where[1]:.0f} deg, theta3 {where[2]:.0f} deg)")
    print(f"downward tip force left at the continuous rating: min {down.min():.3f} N, max {down.max():.3f} N")


if __name__ == "__main__":
    common.run(main)
