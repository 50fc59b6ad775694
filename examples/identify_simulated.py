"""Identify a simulated PHANToM whose parameters differ from the report's by 10-30 %, and plot
the measured torques of a held-out run against those predicted by the identified model and
by the report's.

The pipeline is a real device's: an optimised excitation trajectory, a log of quantized
positions and commanded torques (here from phantom_pin.identification.simulation, with
friction and torque noise), phantom_pin.identification.estimation, and the written
parameters. The held-out run follows another trajectory (a different seed).
"""

from __future__ import annotations

import dataclasses

import matplotlib.pyplot as plt
import numpy as np

import common
from phantom_pin import Phantom, describe
from phantom_pin.identification import constants, estimation, excitation, simulation
from phantom_pin.identification.base import Structured
from phantom_pin.identification.regressor import Regressor

FACTORS = {"ma": 1.2, "Iaxx": 1.2, "Iayy": 1.2, "Iazz": 1.2, "mc": 0.85, "Icxx": 0.85, "Icyy": 0.85,
           "Iczz": 0.85, "mbe": 1.25, "l5": 1.1, "Ibexx": 1.15, "Ibeyy": 1.2, "Ibezz": 1.3,
           "mdf": 1.3, "l6": 0.9, "Idfxx": 1.2, "Idfyy": 1.1, "Idfzz": 1.25, "Ibaseyy": 1.15}


def run_device(phantom, trajectory, duration, truth, seed):
    """A log of the simulated device ``truth`` (ReportParameters) with the friction of
    phantom's law at other coefficients, fed forward with phantom's report model."""
    config = phantom.config
    resolution = 2 * np.pi / (1024 * 4 * np.array(config.actuation.ratios))
    friction = dataclasses.replace(config.actuation.friction, viscous=8e-4, coulomb=0.015)
    return simulation.simulate(trajectory, duration, truth, config.report, friction,
                               torque_noise=0.005, resolution=resolution, seed=seed)


def main(argv: list[str] | None) -> None:
    parser = common.parser(__doc__.splitlines()[0])
    parser.add_argument("--duration", type=float, default=10.0, help="seconds of identification log")
    parser.add_argument("--iterations", type=int, default=15, help="excitation optimiser iterations")
    args = parser.parse_args(argv)
    path = common.output(args, "identify_simulated.png")
    description = describe()                           # the report's model: the prior and the controller's
    phantom = Phantom(description)
    p = description.config.report
    truth = dataclasses.replace(p, **{k: getattr(p, k) * f for k, f in FACTORS.items()})
    design = excitation.optimise(description, iterations=args.iterations, restarts=1)
    print(f"excitation: condition number {design.condition:.3g}")
    fit = estimation.estimate(run_device(phantom, design.trajectory, args.duration, truth, 0), phantom)
    print("residual RMS per joint [N m]: " + " ".join(f"{r:.3g}" for r in fit.rms))
    held_out = excitation.optimise(description, iterations=1, restarts=1, seed=7).trajectory
    log = run_device(phantom, held_out, 5.0, truth, 1)
    theta, dtheta, ddtheta, tau = estimation.filtered(log, 20.0)
    phi, _ = estimation.base_regressor(Structured(Regressor(phantom)), theta, dtheta, ddtheta)
    identified = phi @ np.concatenate([fit.constants, fit.beta[8:]])
    report = phi @ constants.nominal(description)
    step = max(1, int(log.rate / (5 * 20.0)))          # estimation.filtered's decimation
    t = estimation.EDGE + np.arange(len(tau)) * step / log.rate
    errors = {}
    figure, axes = plt.subplots(3, 1, figsize=(9, 8), sharex=True)
    for j, axis in enumerate(axes):
        axis.plot(t, tau[:, j], "k", lw=2, label="measured (commanded, filtered)")
        axis.plot(t, identified[:, j], "C0", label="identified model")
        axis.plot(t, report[:, j], "C3--", label="report's parameters")
        axis.set_ylabel(f"tau{j + 1} [N m]")
    axes[0].legend(loc="upper right", fontsize=8)
    axes[-1].set_xlabel("time [s]")
    for name, prediction in (("identified", identified), ("report", report)):
        errors[name] = np.sqrt(((prediction - tau) ** 2).mean() / (tau**2).mean())
    figure.suptitle(f"held-out torques: RMS error identified {100 * errors['identified']:.1f} %, "
                    f"report {100 * errors['report']:.1f} %")
    figure.savefig(path, dpi=100)
    print(f"held-out RMS torque error: identified {100 * errors['identified']:.2f} %, "
          f"report {100 * errors['report']:.2f} %")
    print(f"wrote {path}")


if __name__ == "__main__":
    common.run(main)
