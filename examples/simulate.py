"""Free swing: the unpowered arm released from rest, integrated with RK4; joint angles
and energy plotted.

No torque acts (tau = 0), there is no friction, and the joint limits are not modelled
(the real arm would hit its stops), so total energy T + V must stay constant: its drift
measures the integration error. T = 1/2 dtheta^T M(theta) dtheta (J), V from Pinocchio
(Phantom.potential_energy, J).
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

import common
from phantom_pin import Phantom, PhantomPinError


def main(argv: list[str] | None = None) -> None:
    cli = common.parser(__doc__.splitlines()[0])
    cli.add_argument("--theta", type=float, nargs=3, default=[0.3, 0.8, 0.4], metavar="T",
                     help="initial posture (rad), released at rest")
    cli.add_argument("--duration", type=float, default=2.0, help="simulated time (s)")
    cli.add_argument("--dt", type=float, default=1e-3, help="RK4 step (s)")
    args = cli.parse_args(argv)
    if not (args.duration > 0 and 0 < args.dt <= args.duration):
        raise PhantomPinError("--duration, --dt: expected 0 < dt <= duration (s)")
    figure_path = common.output(args, "simulate.png")
    phantom = Phantom()

    def rate(state: np.ndarray) -> np.ndarray:  # d/dt (theta, dtheta) with tau = 0
        return np.concatenate([state[3:], phantom.forward_dynamics(state[:3], state[3:], np.zeros(3))])

    steps = int(round(args.duration / args.dt))
    states = np.empty((steps + 1, 6))
    states[0] = np.concatenate([args.theta, np.zeros(3)])
    for k in range(steps):
        x = states[k]
        k1 = rate(x)
        k2 = rate(x + 0.5 * args.dt * k1)
        k3 = rate(x + 0.5 * args.dt * k2)
        k4 = rate(x + args.dt * k3)
        states[k + 1] = x + args.dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    theta, dtheta = states[:, :3], states[:, 3:]
    kinetic = 0.5 * np.einsum("ni,nij,nj->n", dtheta, phantom.mass_matrix(theta), dtheta)
    potential = phantom.potential_energy(theta)
    total = kinetic + potential
    time = np.arange(steps + 1) * args.dt
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
    print(f"{steps} RK4 steps of {args.dt} s; kinetic energy peaks at {kinetic.max():.4e} J")
    print(f"energy drift: max |E(t) - E(0)| = {np.abs(total - total[0]).max():.3e} J")


if __name__ == "__main__":
    common.run(main)
