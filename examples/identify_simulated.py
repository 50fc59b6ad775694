"""Identify a simulated PHANToM Premium 1.5 built from the public CAD (mahilab/Phantom: products of
inertia, centres of mass off the segments' axes; model premium_1_5_cad) starting from the
report's model, and plot the torques of a held-out trajectory against those predicted by the
general identification, by the report-structure identification and by the report's parameters.

The pipeline is a real device's: an optimised excitation trajectory, the device tracking it
(phantom_pin.identification.data.simulation.track: the device's own plant with friction, 2 mN m of
torque noise and its encoders), a log of the encoder's angles and the commanded torques,
phantom_pin.identification.estimate, and the written --params overlay. The held-out motion is
another excitation (another seed), 5 s long.
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

import common
from phantom_pin import Device, Phantom, describe
from phantom_pin.identification import estimate, optimise
from phantom_pin.identification.data import simulation
from phantom_pin.identification.verdict.overlays import overlay
from phantom_pin.identification.verdict.result import recommendation

#: The simulated device's friction (N m s/rad, N m) and torque noise (N m, 1 sigma).
VISCOUS, COULOMB, NOISE = 6e-4, 0.012, 0.002


def run_device(device: Device, design, duration: float, seed: int):
    """The device's log along an excitation (Excitation) for ``duration`` s at 1 kHz."""
    t = np.arange(int(round(duration * 1000)) + 1) / 1000
    theta, dtheta, ddtheta = design.trajectory(t)
    feedforward = Phantom(describe()).inverse_dynamics(theta, dtheta, ddtheta)   # the report's model
    return simulation.track(device, t, theta, dtheta, feedforward, torque_noise=NOISE, seed=seed)


def main(argv: list[str] | None) -> None:
    parser = common.parser(__doc__.splitlines()[0])
    parser.add_argument("--duration", type=float, default=20.0, help="seconds of identification log")
    parser.add_argument("--iterations", type=int, default=30, help="excitation optimiser iterations")
    args = parser.parse_args(argv)
    path = common.output(args, "identify_simulated.png")
    phantom = Phantom(describe())                             # the report's model: the prior
    device = Device(Phantom(describe("premium_1_5_cad", overrides={"actuation.friction.viscous": VISCOUS,
                                                                   "actuation.friction.coulomb": COULOMB})))
    design = optimise(phantom, iterations=args.iterations, restarts=1)
    print(f"excitation: condition number {design.condition:.3g} (general), {design.report_condition:.3g} (report)")
    log = run_device(device, design, args.duration, 0)
    fits = {structure: estimate(log, phantom, structure=structure) for structure in ("general", "report")}
    for structure, fit in fits.items():
        print(f"{structure}: residual RMS per joint [N m] " + " ".join(f"{r:.3g}" for r in fit.rms)
              + "".join(f"; problem: {p}" for p in fit.problems))
    print(recommendation(fits["general"]) or "the report's structure suffices")
    # the held-out motion: each model's inverse dynamics and friction against the device's
    t = np.arange(5001) / 1000
    theta, dtheta, ddtheta = optimise(phantom, iterations=1, restarts=1, seed=7).trajectory(t)
    truth = device.phantom.inverse_dynamics(theta, dtheta, ddtheta) + device.friction(dtheta)
    predictions = {"report's parameters": phantom.inverse_dynamics(theta, dtheta, ddtheta)
                   + phantom.config.actuation.friction.torque(dtheta)}
    for structure, fit in fits.items():
        identified = Device(Phantom(describe(overrides=overlay(fit)[0])))
        predictions[f"identified ({structure})"] = identified.phantom.inverse_dynamics(theta, dtheta, ddtheta) \
            + identified.friction(dtheta)
    errors = {name: float(np.sqrt(((p - truth) ** 2).mean() / (truth**2).mean())) for name, p in predictions.items()}
    figure, axes = plt.subplots(3, 1, figsize=(9, 8), sharex=True)
    for j, axis in enumerate(axes):
        axis.plot(t, truth[:, j], "k", lw=2, label="device (true torque of the motion)")
        for (name, prediction), style in zip(predictions.items(), ("C3--", "C0", "C1:")):
            axis.plot(t, prediction[:, j], style, label=f"{name}: {100 * errors[name]:.2f} % RMS")
        axis.set_ylabel(f"tau{j + 1} [N m]")
    axes[0].legend(loc="upper right", fontsize=8)
    axes[-1].set_xlabel("time [s]")
    figure.suptitle("held-out trajectory: torques of the CAD device and of the models")
    figure.savefig(path, dpi=100)
    print("held-out RMS torque error: " + ", ".join(f"{name} {100 * e:.2f} %" for name, e in errors.items()))
    print(f"wrote {path}")


if __name__ == "__main__":
    common.run(main)
