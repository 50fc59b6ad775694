"""Gravity compensation: the torques (N m) that hold the arm still across its workspace.

theta1 turns the arm about the vertical, so it does not change gravity torques; the map
spans theta2 x theta3 inside the joint limits. Pinocchio (Phantom.gravity) is compared
with the report's corrected eqs 93-94 (closed_form.gravity), and the worst holding
torque with each motor's continuous limit (the URDF's effort limit).
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

import common
from phantom_pin import Phantom, closed_form


def main(argv: list[str] | None = None) -> None:
    args = common.parser(__doc__.splitlines()[0]).parse_args(argv)
    figure_path = common.output(args, "gravity_compensation.png")
    phantom = Phantom()
    limits = phantom.config.limits                                   # the URDF's joint box
    theta2 = np.linspace(limits.lower[1], limits.upper[1], 61)
    theta3 = np.linspace(limits.lower[2], limits.upper[2], 61)
    grid = np.stack(np.meshgrid(theta2, theta3, indexing="ij"), axis=-1)
    theta = np.concatenate([np.zeros(grid.shape[:2] + (1,)), grid], axis=-1)
    tau = phantom.gravity(theta)                                     # (61, 61, 3) N m
    difference = np.abs(tau - closed_form.gravity(theta, phantom.config.report)).max()
    figure, axes = plt.subplots(1, 2, figsize=(10, 4), constrained_layout=True)
    for axis, joint in zip(axes, (1, 2)):
        image = axis.pcolormesh(theta3, theta2, tau[..., joint], shading="auto", cmap="coolwarm")
        axis.set(xlabel="theta3 [rad]", ylabel="theta2 [rad]", title=f"tau{joint + 1} holding torque")
        figure.colorbar(image, ax=axis, label="N m")
    figure.savefig(figure_path, dpi=120)
    limits = phantom.model.effortLimit
    worst = np.abs(tau).reshape(-1, 3).max(axis=0)
    print(f"wrote {figure_path}")
    print(f"Phantom.gravity vs closed_form.gravity over {theta.shape[0] * theta.shape[1]} "
          f"postures: max difference {difference:.2e} N m")
    for joint in (1, 2):
        print(f"joint{joint + 1}: worst holding torque {worst[joint]:.4f} N m = "
              f"{100 * worst[joint] / limits[joint]:.1f}% of the continuous limit {limits[joint]:.3f} N m")


if __name__ == "__main__":
    common.run(main)
