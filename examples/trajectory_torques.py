"""Torques along a minimum-jerk reach: the tip moves on a straight line in the report's
frame s with the minimum-jerk profile s(tau) = 10 tau^3 - 15 tau^4 + 6 tau^5 (Flash and
Hogan, 1985); the joint motion comes from inverse kinematics and the tip Jacobian, the
torques (N m) from Phantom.inverse_dynamics, split into gravity N(theta) and the rest.

Joint rates: dtheta = Jp^-1 dp, joint accelerations: ddtheta = Jp^-1 (ddp - dJp dtheta),
where Jp = Jv - [p]x Jw is the tip's linear-velocity Jacobian in frame s built from the
spatial Jacobian (eq. 22) and dJp dtheta is a central difference of Jp along dtheta.
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

import common
from phantom_pin import Phantom, PhantomPinError

#: Default start and end postures (rad); the reach is between their tip positions.
START, END = [-0.5, 0.2, 0.3], [0.5, 0.5, 0.6]


def tip_jacobian(phantom: Phantom, theta: np.ndarray) -> np.ndarray:
    """(..., 3, 3): d(tip position in s)/d(theta), from J^s = (Jv, Jw): Jv - [p]x Jw."""
    spatial = phantom.spatial_jacobian(theta)
    v, w = spatial[..., :3, :], spatial[..., 3:, :]       # column j: the twist of joint j
    p = phantom.forward_kinematics(theta)[..., :3, 3:]    # (..., 3, 1) tip position
    return v + np.cross(w, p, axisa=-2, axisb=-2, axisc=-2)   # velocity of the tip point


def reach(phantom: Phantom, start: np.ndarray, end: np.ndarray, duration: float,
          samples: int = 301) -> dict[str, np.ndarray]:
    """The minimum-jerk reach from ``start`` to ``end`` (m, frame s) in ``duration`` s at
    ``samples`` instants: time (s), path (m), theta (rad), dtheta (rad/s), ddtheta
    (rad/s^2), torque (N m) and gravity (N m), each with one row per instant."""
    time = np.linspace(0.0, duration, samples)
    tau_ = time / duration
    shape = 10 * tau_**3 - 15 * tau_**4 + 6 * tau_**5
    rate = (30 * tau_**2 - 60 * tau_**3 + 30 * tau_**4) / duration
    acceleration = (60 * tau_ - 180 * tau_**2 + 120 * tau_**3) / duration**2
    delta = end - start
    path, velocity, accel = (start + np.outer(shape, delta), np.outer(rate, delta),
                             np.outer(acceleration, delta))
    theta = phantom.inverse_kinematics(path)                         # raises if unreachable
    jacobian = tip_jacobian(phantom, theta)
    dtheta = np.linalg.solve(jacobian, velocity[..., None])[..., 0]
    eps = 1e-6
    djacobian = (tip_jacobian(phantom, theta + eps * dtheta)
                 - tip_jacobian(phantom, theta - eps * dtheta)) / (2 * eps)
    bias = np.einsum("nij,nj->ni", djacobian, dtheta)
    ddtheta = np.linalg.solve(jacobian, (accel - bias)[..., None])[..., 0]
    return {"time": time, "path": path, "theta": theta, "dtheta": dtheta, "ddtheta": ddtheta,
            "torque": phantom.inverse_dynamics(theta, dtheta, ddtheta), "gravity": phantom.gravity(theta)}


def main(argv: list[str] | None = None) -> None:
    cli = common.parser(__doc__.splitlines()[0])
    cli.add_argument("--start", type=float, nargs=3, metavar="P", help="tip start (m, frame s)")
    cli.add_argument("--end", type=float, nargs=3, metavar="P", help="tip end (m, frame s)")
    cli.add_argument("--duration", type=float, default=0.6, help="movement time (s)")
    args = cli.parse_args(argv)
    if not args.duration > 0:
        raise PhantomPinError("--duration: expected a positive number of seconds")
    figure_path = common.output(args, "trajectory_torques.png")
    phantom = Phantom()
    start = np.array(args.start) if args.start else phantom.forward_kinematics(START)[:3, 3]
    end = np.array(args.end) if args.end else phantom.forward_kinematics(END)[:3, 3]
    result = reach(phantom, start, end, args.duration)
    time, theta, torque, gravity = (result[k] for k in ("time", "theta", "torque", "gravity"))
    figure, axes = plt.subplots(3, 1, figsize=(8, 8), sharex=True, constrained_layout=True)
    axes[0].plot(time, theta, label=["theta1", "theta2", "theta3"])
    axes[0].set(ylabel="joint angle [rad]", title="minimum-jerk reach in frame s")
    axes[1].plot(time, torque, label=["tau1", "tau2", "tau3"])
    axes[1].set(ylabel="torque [N m]")
    axes[2].plot(time, torque - gravity, label=["tau1 - N1", "tau2 - N2", "tau3 - N3"])
    axes[2].set(xlabel="time [s]", ylabel="torque without gravity [N m]")
    for axis in axes:
        axis.legend()
    figure.savefig(figure_path, dpi=120)
    print(f"wrote {figure_path}")
    print(f"reach from {np.round(start, 4)} to {np.round(end, 4)} m (frame s) in {args.duration} s")
    print(f"peak |tau| per joint [N m]: {np.round(np.abs(torque).max(axis=0), 4)}")


if __name__ == "__main__":
    common.run(main)
