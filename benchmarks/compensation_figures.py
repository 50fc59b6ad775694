"""The numbers of docs/feel.md's "Compensation beyond gravity": what the hand feels through the
OpenHaptics servo loop on the simulated device (phantom_pin.interfaces.openhaptics.hand, 1 kHz,
the encoder's counts where the model has public encoder data), per model at the posture given
(default the nominal one of docs/feel.md, theta = 0):

- the mass felt pushing the tip from rest along OpenHaptics' x, y, z (g), against Lambda along
  the same axis, without and with a share kappa of the inertia compensated;
- the backdrive force dragging the tip at 20 mm/s along each axis (mN), with gravity
  compensated alone and with friction too, for each dead band of --dead-bands;
- how far the tip wanders at rest in 2 s with friction compensated, for each dead band (mm);
- the stiffest wall (N/m, normal along z) that holds the hand's 0.5 N push still, with gravity
  compensated, with friction too, and with friction and a virtual damper B, against Colgate and
  Brown's passivity bound K <= 2 (b - |B|) / T for the device's own viscous damping b along the
  wall's normal (b = n^T J^-T D J^-1 n, D the joints' viscous coefficients; J. E. Colgate and
  J. M. Brown, "Factors affecting the Z-Width of a haptic display", IEEE ICRA 1994).

    python benchmarks/compensation_figures.py [--theta T1 T2 T3] [--kappa 0.6] [--damping 3] [--plot FILE.html]

--plot writes the page of docs/feel.md's figures (the tip pushed from rest without and with the
inertia compensated; the wall's depth with gravity, with friction and with friction and B
compensated), matplotlib's SVG in one HTML file.
"""

from __future__ import annotations

import argparse

import numpy as np

from phantom_pin import Device
from phantom_pin.config import models
from phantom_pin.interfaces.openhaptics import Compensator, hand
from phantom_pin.viewer.plots import Curve, Panel, figure_svg, page, write_page

AXES = {"x": np.array([1.0, 0.0, 0.0]), "y": np.array([0.0, 1.0, 0.0]), "z": np.array([0.0, 0.0, 1.0])}


def along(name: str, theta: np.ndarray, u: np.ndarray) -> tuple[float, float]:
    """(1 / (u^T Lambda^-1 u) kg, the device's viscous damping along u, N s/m)."""
    device = Device.from_model(name)
    jacobian = device.tip_jacobian(theta)
    inverse = jacobian @ np.linalg.solve(device.phantom.mass_matrix(theta), jacobian.T)
    back = np.linalg.inv(jacobian)                                  # tip velocity -> joint rates
    damping = back.T @ np.diag(device.config.actuation.friction.viscous) @ back
    return 1.0 / (u @ inverse @ u), float(u @ damping @ u)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--theta", type=float, nargs=3, default=[0.0, 0.0, 0.0], metavar=("T1", "T2", "T3"),
                        help="the posture (rad; default the nominal one, device.feel.nominal_posture's)")
    parser.add_argument("--kappa", type=float, default=0.6)
    parser.add_argument("--damping", type=float, default=3.0, help="the wall's virtual damper B (N s/m)")
    parser.add_argument("--dead-bands", type=float, nargs="+", default=[0.0, 0.01, 0.05])
    parser.add_argument("--plot", help="write the figures' page (HTML) here")
    parser.add_argument("--force", action="store_true", help="overwrite --plot's file")
    args = parser.parse_args()
    theta = np.array(args.theta)
    print(f"# posture theta = {args.theta} rad; kappa = {args.kappa}; 1 kHz")
    print("\n| model | axis | Lambda (g) | felt (g) | felt, inertia compensated (g) | ratio |")
    print("|---|---|---|---|---|---|")
    for name in models():
        for axis, u in AXES.items():
            reference = along(name, theta, u)[0]
            plain = hand.apparent_mass(Compensator(name, "joint_torque"), theta, u)
            less = hand.apparent_mass(Compensator(name, "joint_torque", ("gravity", "inertia"), kappa=args.kappa),
                                      theta, u)
            print(f"| {name} | {axis} | {reference * 1e3:.1f} | {plain * 1e3:.1f} | {less * 1e3:.1f} | "
                  f"{plain / less:.2f} |")
    print("\n| model | axis | backdrive (mN) | " + " | ".join(f"friction compensated, dead band {d:g} rad/s (mN)"
                                                       for d in args.dead_bands) + " |")
    print("|---|---|---|" + "---|" * len(args.dead_bands))
    for name in models():
        for axis, u in AXES.items():
            plain = hand.backdrive(Compensator(name, "joint_torque"), theta, u)
            cells = [hand.backdrive(Compensator(name, "joint_torque", ("gravity", "friction"), dead_band=d), theta, u)
                     for d in args.dead_bands]
            print(f"| {name} | {axis} | {plain * 1e3:.1f} | " + " | ".join(f"{c * 1e3:.2f}" for c in cells) + " |")
    print("\n| model | " + " | ".join(f"drift at rest in 2 s, dead band {d:g} rad/s (mm)" for d in args.dead_bands)
          + " |")
    print("|---|" + "---|" * len(args.dead_bands))
    for name in models():
        cells = [hand.rest_drift(Compensator(name, "joint_torque", ("gravity", "friction"), dead_band=d), theta)
                 for d in args.dead_bands]
        print(f"| {name} | " + " | ".join(f"{c * 1e3:.3f}" for c in cells) + " |")
    zero, normal = np.zeros(3), AXES["z"]
    print("\n| model | b along z (N s/m) | Colgate-Brown 2 b / T (N/m) | stiffest wall, gravity compensated (N/m) | "
          "+ friction (N/m) | "
          f"+ friction, B = {args.damping:g} N s/m |")
    print("|---|---|---|---|---|---|")
    for name in models():
        b = along(name, zero, normal)[1]
        cells = [hand.stiffest_wall(lambda terms=terms, name=name: Compensator(name, "joint_torque", terms),
                                    zero, normal, damping=damping)
                 for terms, damping in ((("gravity",), 0.0), (("gravity", "friction"), 0.0),
                                        (("gravity", "friction"), args.damping))]
        print(f"| {name} | {b:.4f} | {2 * b / 1e-3:.0f} | " + " | ".join(f"{c:.0f}" for c in cells) + " |")
    if args.plot:
        write_page(args.plot, figures(theta, args.kappa, args.damping), force=args.force, argument="--plot")
        print(f"\nwrote {args.plot}")


def figures(theta: np.ndarray, kappa: float, damping: float, name: str = "touch") -> str:
    """The page: the tip pushed with 20 mN along each axis from rest, without and with the
    inertia compensated (mm over s); the wall's depth (mm over s) at 1500 N/m."""
    colours = ("#1f77b4", "#ff7f0e", "#2ca02c")
    pushes = []
    for axis, u in AXES.items():
        curves = []
        inertia = Compensator(name, "joint_torque", ("gravity", "inertia"), kappa=kappa)
        for label, compensator, style in (("gravity", Compensator(name, "joint_torque"), "-"),
                                          (f"+ inertia, kappa {kappa:g}", inertia, "--")):
            run = hand.run(compensator, theta, 0.1, lambda t, x, dx, u=u: 0.02 * u, friction=False)
            curves.append(Curve(run.t, (run.tip - run.tip[0]) @ u * 1e3, label, f"push-{axis}-{style}",
                                colours["xyz".index(axis)], style))
        pushes.append(Panel(f"{name}: pushed with 20 mN along {axis}", "displacement [mm]", curves))
    normal, walls = AXES["z"], []
    offset = float(normal @ Device.from_model(name).phantom.forward_kinematics(np.zeros(3))[:3, 3])
    for label, terms, b in (("gravity", ("gravity",), 0.0), ("+ friction", ("gravity", "friction"), 0.0),
                            (f"+ friction, B {damping:g} N s/m", ("gravity", "friction"), damping)):
        run = hand.run(Compensator(name, "joint_torque", terms), np.zeros(3), 1.0, lambda t, x, dx: 0.5 * normal,
                       wall=(normal, offset, 1500.0, b))
        walls.append(Curve(run.t, (run.tip @ normal - offset) * 1e3, label, f"wall-{len(walls)}", colours[len(walls)]))
    wall = Panel(f"{name}: a 1500 N/m wall, 0.5 N pushing", "depth [mm]", walls)
    facts = [("model", name), ("posture (rad)", str(theta.tolist())), ("servo rate", "1 kHz")]
    return page("What the hand feels: compensation beyond gravity", facts,
                [("The tip pushed from rest", figure_svg(pushes)), ("A virtual wall", figure_svg([wall]))])


if __name__ == "__main__":
    main()
