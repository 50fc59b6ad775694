"""A virtual wall rendered at 1 kHz: force and penetration over time, and the highest
stable wall stiffness against the sampling rate in both plants (phantom_pin.simulate and
MuJoCo on the MJCF, phantom_pin.device.mujoco_plant), compared with the passivity bound.

The wall is the floor y <= y_wall (frame s: y up) through the tip of the posture --posture.
The controller (sampled at the rate, zero-order hold) renders F = K * depth along +y while
the tip is below the floor (a pure spring, virtual damping B = 0), compensates gravity,
and adds a steady 1 N push down that stands for the user's hand (the motors emulate it, so
it is sampled and saturated too). The plant is phantom_pin.simulate's: rigid body, rotors,
friction, hard stops, saturation. Each run starts at rest, 1 mm deeper than the static
penetration F_push / K.

Stability: a run (0.4 s) is stable when the peak-to-peak penetration over its last 0.1 s is
less than half that over its first 0.1 s (the bounce decays); the highest stable stiffness of
a rate is the last of a geometric grid (250 N/m x sqrt 2 ** k) before the first unstable one.
Colgate and Schenkel's passivity condition b > K T / 2 + |B| gives K < 2 b / T, with b the
device's physical damping at the tip along the wall normal, b_n = n^T J^-T B J^-1 n, B the
diagonal of each joint's viscous friction (b n^T (J J^T)^-1 n when the joints agree).
Passivity is sufficient, not necessary: the device's Coulomb friction dissipates too (it
stops the arm dead below its level), so the measured limit may exceed the bound.
"""

from __future__ import annotations

import math

import matplotlib.pyplot as plt
import numpy as np

import common
from phantom_pin import Device, PhantomPinError, simulate

NORMAL = np.array([0.0, 1.0, 0.0])   # the wall's outward normal in frame s (up)
PUSH = 1.0                           # N, the hand's push into the wall
OFFSET = 1e-3                        # m, initial depth beyond the static penetration
DURATION, SWEEP_DURATION, WINDOW = 0.5, 0.4, 0.1   # s: the plotted runs, the sweep's, the windows
GRID = 250.0 * np.sqrt(2.0) ** np.arange(13)         # N/m, 250 .. 16000


PLANTS = ("simulate", "mujoco")


def run_plant(plant: str, start, duration, controller, rate, device):
    """phantom_pin.simulate, or the same loop on the MJCF in MuJoCo (its step the longest that
    divides the period 1 / rate and is at most the MJCF's 1 ms)."""
    if plant == "simulate":
        return simulate(start, duration, controller, rate=rate, device=device)
    from phantom_pin.device.mujoco_plant import simulate_mujoco
    steps = max(1, math.ceil(1.0 / (rate * 1e-3) * (1 - 1e-12)))   # MuJoCo steps per sample
    return simulate_mujoco(start, duration, controller, rate=rate, device=device, timestep=1.0 / (rate * steps))


def wall_run(device: Device, posture: np.ndarray, stiffness: float, rate: float, duration: float,
             plant: str = "simulate"):
    """One run in ``plant`` (PLANTS): (result, penetration (K,) m, wall force (K,) N, stable?)."""
    phantom = device.phantom
    surface = phantom.forward_kinematics(posture)[:3, 3]             # on the floor (m, frame s)
    start = phantom.inverse_kinematics(surface - (PUSH / stiffness + OFFSET) * NORMAL)

    def controller(t: float, theta: np.ndarray, dtheta: np.ndarray) -> np.ndarray:
        pose = phantom.forward_kinematics(theta)
        depth = (surface - pose[:3, 3]) @ NORMAL
        force = (stiffness * depth if depth > 0 else 0.0) - PUSH
        jacobian = pose[:3, :3] @ phantom.body_jacobian(theta)[:3]  # Device.tip_jacobian, one fk fewer
        return phantom.gravity(theta) + jacobian.T @ (force * NORMAL)

    result = run_plant(plant, start, duration, controller, rate, device)
    depth = (surface - result.tip) @ NORMAL
    first, last = depth[result.t < WINDOW], depth[result.t > duration - WINDOW]
    return result, depth, stiffness * np.maximum(depth, 0.0), bool(np.ptp(last) <= 0.5 * np.ptp(first))


def highest_stable(device: Device, posture: np.ndarray, rate: float, plant: str = "simulate") -> float:
    """The last stiffness of GRID (N/m) before the first unstable one in ``plant``; 0 if GRID[0]
    is unstable."""
    best = 0.0
    for stiffness in GRID:
        if not wall_run(device, posture, stiffness, rate, SWEEP_DURATION, plant)[3]:
            break
        best = stiffness
    return best


def main(argv: list[str] | None = None) -> None:
    cli = common.parser(__doc__.splitlines()[0])
    cli.add_argument("--posture", type=float, nargs=3, default=[0.0, 0.3, 0.4], metavar="T",
                     help="posture whose tip is on the wall (rad)")
    cli.add_argument("--stiffness", type=float, nargs=2, default=[1000.0, 2000.0], metavar="K",
                     help="the two walls plotted over time at 1 kHz (N/m)")
    cli.add_argument("--rates", type=float, nargs="+", default=[250.0, 500.0, 1000.0, 2000.0],
                     help="sampling rates of the stability sweep (Hz)")
    cli.add_argument("--plants", nargs="+", choices=PLANTS, default=list(PLANTS),
                     help="the simulators of the sweep: phantom_pin.simulate and MuJoCo on the MJCF (default both; "
                          "MuJoCo needs the interop extra)")
    args = cli.parse_args(argv)
    for name, values in (("--stiffness", args.stiffness), ("--rates", args.rates)):
        if not all(math.isfinite(x) and x > 0 for x in values):
            raise PhantomPinError(f"{name}: expected finite numbers > 0, got {' '.join(map(str, values))}")
    figure_path = common.output(args, "virtual_wall.png")
    device = Device()
    posture = np.array(args.posture)
    if not device.within_limits(posture):
        raise PhantomPinError(f"--posture: {args.posture} rad is outside the device's stops")
    viscous = np.diag(device.config.actuation.friction.viscous)         # N m s/rad, each joint's
    jacobian = device.tip_jacobian(posture)
    inverse = np.linalg.inv(jacobian)                                    # rad/m: joint rates of a tip velocity
    damping = NORMAL @ inverse.T @ viscous @ inverse @ NORMAL            # N s/m at the tip
    tip_mass = 1.0 / (NORMAL @ jacobian @ np.linalg.inv(device.phantom.mass_matrix(posture)) @ jacobian.T @ NORMAL)

    figure, (penetration_axis, force_axis, sweep_axis) = plt.subplots(3, 1, figsize=(8, 10), constrained_layout=True)
    for stiffness in args.stiffness:
        result, depth, force, stable = wall_run(device, posture, stiffness, 1000.0, DURATION)
        label = f"K = {stiffness:g} N/m ({'stable' if stable else 'unstable'})"
        penetration_axis.plot(result.t, 1e3 * depth, label=label)
        force_axis.plot(result.t, force, label=label)
        settled = depth[result.t > DURATION - WINDOW]
        print(f"1000 Hz, K = {stiffness:g} N/m: {'stable' if stable else 'unstable'}; last {WINDOW} s: "
              f"penetration {1e3 * settled.mean():.4f} mm (F/K = {1e3 * PUSH / stiffness:.4f} mm), "
              f"peak-to-peak {1e3 * np.ptp(settled):.2e} mm")
    penetration_axis.axhline(0.0, color="k", lw=0.8)
    penetration_axis.set(ylabel="penetration [mm]", title=f"virtual wall at 1 kHz, {PUSH:g} N push, "
                                                           f"tip mass {1e3 * tip_mass:.0f} g along the normal")
    force_axis.set(xlabel="time [s]", ylabel="wall force [N]")
    for axis in (penetration_axis, force_axis):
        axis.legend()

    rates = np.array(sorted(args.rates))
    measured = {plant: np.array([highest_stable(device, posture, rate, plant) for rate in rates])
                for plant in args.plants}
    names = {"simulate": "phantom_pin.simulate", "mujoco": "MuJoCo"}
    for (plant, values), style in zip(measured.items(), ("o-", "s--")):
        sweep_axis.loglog(rates, values, style, label=f"highest stable K ({names[plant]})")
    sweep_axis.loglog(rates, 2 * damping * rates, "--", label="passivity bound 2 b / T, b = viscous")
    sweep_axis.set(xlabel="sampling rate [Hz]", ylabel="wall stiffness K [N/m]")
    sweep_axis.legend()
    figure.savefig(figure_path, dpi=120)
    print(f"wrote {figure_path}")
    print(f"tip damping along the normal: viscous b_n = {damping:.4g} N s/m; tip mass {tip_mass:.4f} kg")
    for k, rate in enumerate(rates):
        print(f"rate {rate:g} Hz: highest stable K = " + ", ".join(f"{values[k]:g} N/m ({plant})"
                                                                   for plant, values in measured.items())
              + f"; passivity bound {2 * damping * rate:.4g} N/m (viscous)")


if __name__ == "__main__":
    common.run(main)
