"""``phantom-pin feel``: what the hand feels at the stylus at a posture (phantom_pin.device.feel):
the apparent mass, the backdrive force, the largest tip forces and the workspace, with units."""

from __future__ import annotations

import argparse
import sys

import numpy as np

from phantom_pin.cli.common import add_plot_option, phantom, plot_target, show, vector, write_texts
from phantom_pin.config.sampling import sample_postures
from phantom_pin.device import Device
from phantom_pin.device.feel import DEFAULT_SPEED, Feel, feel
from phantom_pin.viewer import plots

#: The library's argument names and the options that give them (PhantomPinError.argument).
OPTIONS = {"theta": "--theta", "speed": "--speed"}
AXIS_NAMES = ("+x", "-x", "+y", "-y", "+z", "-z")
#: Postures drawn for the workspace's picture (seeded: the page depends on the model alone).
PICTURE_POSTURES = 1000


def _forces(values: np.ndarray) -> str:
    return ", ".join(f"{name} {'unbounded' if not np.isfinite(v) else f'{v:.3f}'}"
                     for name, v in zip(AXIS_NAMES, values))


def text(m: Feel) -> str:
    """The measures as lines with their units and definitions."""
    where = ("the SRDF's zero posture, the nominal one: upper arm horizontal, forearm vertical (orthogonal arms)"
             if m.posture == "zero" else "as given")
    directions = " ".join(vector(d, "{:+.3f}") for d in m.directions.T)
    tip = np.where(abs(m.tip) < 5e-3, 0.0, m.tip)          # no "-0.00"
    lines = [
        f"{m.model} at theta {vector(m.theta, '{:.6g}')} rad ({where}); tip {vector(tip, '{:.2f}')} mm in frame s "
        f"(OpenHaptics' axes: x right, y up, z towards the user); tip Jacobian's condition number {m.condition:.3g}",
        "apparent mass at the tip, Lambda = (J M^-1 J^T)^-1 (J the tip's Jacobian in frame s, M with the rotors):",
        f"  principal masses {vector(m.principal_masses, '{:.2f}')} g along {directions} (frame s)",
        f"  along x, y, z (1 / (u^T Lambda^-1 u)): {vector(m.axis_masses, '{:.2f}')} g",
        "backdrive force at the tip (the friction law through J^-T, gravity held, inertia left out), along the motion:",
        f"  breakaway (each moving joint at its Coulomb torque): x {m.breakaway_along[0]:.4f}, "
        f"y {m.breakaway_along[1]:.4f}, z {m.breakaway_along[2]:.4f} N",
        f"  sliding at {m.speed:g} m/s: x {m.sliding_along[0]:.4f}, y {m.sliding_along[1]:.4f}, "
        f"z {m.sliding_along[2]:.4f} N",
        "largest tip force at this posture, gravity held (Device.tip_force_capacity):",
        f"  peak torques:       {_forces(m.peak_force)} N",
        f"  continuous torques: {_forces(m.continuous_force)} N",
    ]
    if m.nominal_max_force is not None:
        lines.append(f"  OpenHaptics' nominal figures (actuation.yaml): HD_NOMINAL_MAX_FORCE {m.nominal_max_force:g} "
                     f"N, HD_NOMINAL_MAX_STIFFNESS {m.nominal_max_stiffness:g} N/mm")
    box = ", ".join(f"{axis} {lo:.1f}..{hi:.1f}" for axis, lo, hi in zip("xyz", m.box_lower, m.box_upper))
    lines.append(f"workspace the stops allow (the tip in frame s): {box} mm; volume {m.volume:.0f} cm^3 "
                 "(the integral of |det J| over the stops)")
    return "\n".join(lines)


def _mass_panels(m: Feel) -> list[plots.Panel]:
    """The apparent mass m(u) = 1 / (u^T Lambda^-1 u) (g) along the directions u of each coordinate
    plane, drawn as the curve m(u) u."""
    inverse = np.linalg.inv(m.apparent_mass)
    angle = np.linspace(0.0, 2 * np.pi, 361)
    panels = []
    for first, second in ((0, 1), (0, 2), (2, 1)):
        u = np.zeros((len(angle), 3))
        u[:, first], u[:, second] = np.cos(angle), np.sin(angle)
        mass = 1e3 / np.einsum("ni,ij,nj->n", u, inverse, u)
        name = "xyz"[first] + "xyz"[second]
        curve = plots.Curve(mass * u[:, first], mass * u[:, second], "m(u) u", f"apparent-mass-{name}", "#1f77b4")
        panels.append(plots.Panel(f"{'xyz'[second]} against {'xyz'[first]} (g)", f"{'xyz'[second]} [g]", [curve]))
    return panels


def _workspace_panels(device: Device, m: Feel) -> list[plots.Panel]:
    """Tips of seeded postures inside the stops (mm, frame s) in each coordinate plane, the box and
    the posture's tip."""
    theta = sample_postures(device.config.limits, PICTURE_POSTURES, np.random.default_rng(52))
    tips = device.phantom.forward_kinematics(theta)[:, :3, 3] * 1e3
    panels = []
    for first, second in ((0, 1), (0, 2), (2, 1)):
        lo, hi = m.box_lower[[first, second]], m.box_upper[[first, second]]
        name = "xyz"[first] + "xyz"[second]
        curves = [plots.Curve(tips[:, first], tips[:, second], "tips inside the stops", f"workspace-{name}",
                              "#7f7f7f", "none", "."),
                  plots.Curve(np.array([lo[0], hi[0], hi[0], lo[0], lo[0]]),
                              np.array([lo[1], lo[1], hi[1], hi[1], lo[1]]), "box", f"workspace-box-{name}",
                              "#c00000", "--"),
                  plots.Curve(m.tip[[first]], m.tip[[second]], "this posture", f"workspace-tip-{name}", "#1f77b4",
                              "none", "o")]
        panels.append(plots.Panel(f"{'xyz'[second]} against {'xyz'[first]} (mm)", f"{'xyz'[second]} [mm]", curves))
    return panels


def page(device: Device, m: Feel) -> str:
    """The --plot page: the facts as text, the apparent mass in each coordinate plane, the workspace."""
    facts = [(line.strip(), "") for line in text(m).splitlines()]
    return plots.page(f"phantom-pin feel: {m.model}", facts, [
        ("Apparent mass m(u) = 1 / (u^T Λ^-1 u) along each direction u of a coordinate plane (frame s)",
         plots.figure_svg(_mass_panels(m), xlabel="the title's second axis [g]")),
        ("The workspace the stops allow: the tip over postures inside the stops, the box (frame s)",
         plots.figure_svg(_workspace_panels(device, m), xlabel="the title's second axis [mm]"))])


def feel_command(args: argparse.Namespace) -> int:
    """Run ``phantom-pin feel``: the measures printed (or JSON); --plot's page written only once
    every measure is computed."""
    plot = plot_target(args)
    device = Device(phantom(args))
    measures = feel(device, args.theta, speed=args.speed)
    staged = [] if plot is None else [(plot, page(device, measures), "--plot")]
    write_texts(staged)                                     # the page, or nothing
    show(args, measures.as_dict(), text(measures))
    if plot is not None:
        print(f"wrote {plot}", file=sys.stderr)
    return 0


def add_parsers(sub: argparse._SubParsersAction) -> None:
    """The feel command."""
    command = sub.add_parser("feel", help="what the hand feels at the stylus: apparent mass, backdrive force, "
                                          "largest tip forces and the workspace (phantom_pin.device.feel)")
    command.set_defaults(run=feel_command, options=OPTIONS, output=None)
    command.add_argument("--theta", metavar="T", nargs=3, type=float,
                         help="posture (rad, the report's theta; inside the stops; default the SRDF's zero, the "
                              "nominal orthogonal-arms posture)")
    command.add_argument("--speed", type=float, default=DEFAULT_SPEED,
                         help=f"tip speed of the sliding backdrive force (m/s, default {DEFAULT_SPEED:g})")
    command.add_argument("--json", action="store_true", help="print JSON")
    command.add_argument("--force", "-f", action="store_true", help="overwrite an existing --plot file")
    add_plot_option(command, "the apparent mass in each coordinate plane and the workspace")
