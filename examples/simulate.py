"""Free swing: the unpowered arm released from rest, integrated by phantom_pin.simulate (RK4,
one step per sample); joint angles and energy plotted.

No torque acts (tau = 0), friction, the stops and saturation are off (the real arm would hit
its stops), so total energy T + V must stay constant: its drift measures the integration
error. T = 1/2 dtheta^T M(theta) dtheta (J), V from Pinocchio (Phantom.potential_energy, J).
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

import common
from phantom_pin import Phantom, PhantomPinError, simulate


def main(argv: list[str] | None = None) -> None:
    cli = common.parser(__doc__.splitlines()[0])
    cli.add_argument("--theta", type=float, nargs=3, default=[0.3, 0.8, 0.4], metavar="T",
                     help="initial posture (rad), released at rest")
    cli.add_argument("--duration", type=float, default=2.0, help="simulated time (s)")
    cli.add_argument("--dt", type=float, default=1e-3, help="sample period (s); RK4 steps of at most 1 ms")
    args = cli.parse_args(argv)
    if not (args.duration > 0 and 0 < args.dt <= args.duration):
        raise PhantomPinError("--duration, --dt: expected 0 < dt <= duration (s)")
    figure_path = common.output(args, "simulate.png")
    phantom = Phantom()

    steps = int(round(args.duration / args.dt))
    result = simulate(args.theta, steps * args.dt, rate=1 / args.dt, friction=False, hard_stops=False,
                      saturation=False)
    theta, dtheta, time = result.theta, result.dtheta, result.t
    kinetic = 0.5 * np.einsum("ni,nij,nj->n", dtheta, phantom.mass_matrix(theta), dtheta)
    potential = phantom.potential_energy(theta)
    total = kinetic + potential
    figure, (top, bottom) = plt.subplots(2, 1, figsize=(8, 6), sharex=True, constrained_layout=True)
    top.plot(time, theta, label=["theta1", "theta2", "theta3"])
    top.set(ylabel="joint angle [rad]", title=f"free swing from theta = {args.theta} rad")
    top.legend()
    bottom.plot(time, kinetic, label="kinetic T")
    bottom.plot(time, potential - potential[0], label="potential V - V(0)")
    bottom.plot(time, total - total[0], label="drift (T + V) - E(0)")
    bottom.set(xlabel="time [s]", ylabel="energy [J]")
    bottom.legend()
    figure.savefig(figure_path, dpi=120)
    print(f"wrote {figure_path}")
    print(f"{steps} samples of {args.dt} s, {result.substeps} RK4 step(s) each; "
          f"kinetic energy peaks at {kinetic.max():.4e} J")
    print(f"energy drift: max |E(t) - E(0)| = {np.abs(total - total[0]).max():.3e} J")


if __name__ == "__main__":
    common.run(main)
