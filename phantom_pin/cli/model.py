"""The model's commands of ``phantom-pin``: info, check, fk, ik, dynamics, the generated files
(urdf, srdf, mjcf, links) and show."""

from __future__ import annotations

import argparse
import os
import webbrowser
from pathlib import Path
from typing import Any

import numpy as np

from phantom_pin._progress import Progress
from phantom_pin._validation import within_box
from phantom_pin.cli import device
from phantom_pin.cli.common import (
    Once,
    add_gimbal,
    description,
    output,
    overrides,
    phantom,
    positive_integer,
    show,
    vector,
    warn,
    warn_gimbal,
    warn_limits,
    write_text,
    write_texts,
)
from phantom_pin.config.types import Gimbal
from phantom_pin.description.build import CONVENTIONS, driver_urdf, links_yaml
from phantom_pin.dynamics import verification
from phantom_pin.dynamics.loader import load
from phantom_pin.dynamics.phantom import Phantom
from phantom_pin.exceptions import LogError, PhantomPinError
from phantom_pin.identification.data import io

THREE = {"nargs": 3, "type": float}
#: The columns show --trajectory reads (s, rad: the report's theta), and a stylus gimbal's
#: (rad, OpenHaptics' raw gimbal angles), optional.
MOTION_COLUMNS = ("t", "theta1", "theta2", "theta3")
GIMBAL_COLUMNS = ("gimbal1", "gimbal2", "gimbal3")
def info(args: argparse.Namespace) -> int:
    """Joints, links, rotor and device data of the model, with their sources."""
    given = overrides(args)
    robot = Phantom(description(args, given))
    model, actuation = robot.model, robot.config.actuation
    joints = [{"name": model.names[i], "lower": float(model.lowerPositionLimit[i - 1]),
               "upper": float(model.upperPositionLimit[i - 1]),
               "velocity": float(model.velocityLimit[i - 1]), "effort": float(model.effortLimit[i - 1]),
               "armature": float(model.armature[i - 1]),
               "ratio": None if actuation.ratios is None else actuation.ratios[i - 1]} for i in (1, 2, 3)]
    gimbal = robot.config.gimbal
    every = {**robot.config.links, **(gimbal.links if gimbal else {})}  # the URDF's links, as configured
    links: list[dict[str, Any]] = [{"name": name, "mass": float(link.mass), "com": [float(c) for c in link.com],
                                    "inertia": [float(i) for i in link.inertia]} for name, link in every.items()]
    data: dict[str, Any] = {"model": robot.config.name, "joints": joints, "links": links,
            "rotor_inertia": None if actuation.motor is None else actuation.motor.rotor_inertia}
    lines = ["joint    lower[rad] upper[rad] vel[rad/s] effort[Nm] armature[kg m2] ratio"]
    lines += [f"{j['name']:8} {j['lower']:10.3f} {j['upper']:10.3f} {j['velocity']:10.2f} "
              f"{j['effort']:10.3f} {j['armature']:15.4e} "
              f"{'-' if j['ratio'] is None else format(j['ratio'], '5.1f'):>5}" for j in joints]
    width = max(len("link"), *(len(lk["name"]) for lk in links))
    lines += ["", f"{'link':{width}} mass[kg]  com[m] (link frame)       inertia xx xy xz yy yz zz at the COM [kg m2]"]
    lines += [f"{lk['name']:{width}} {lk['mass']:8.4f}  {vector(lk['com'], '{:7.4f}'):26}"
              f"{vector(lk['inertia'], '{:.3e}')}" for lk in links]
    lines += ["", "rotor inertia: not public (no armature; the links carry the rotors)" if actuation.motor is None
              else f"rotor inertia {actuation.motor.rotor_inertia:.3e} kg m2 (each motor)"]
    if gimbal is not None:
        data["gimbal"], gimbal_lines = _gimbal_info(robot, gimbal)
        lines += gimbal_lines
    count = len(given)
    data["overrides"] = count
    lines.insert(0, f"model {robot.config.name}" + (f", with {count} overridden number(s) (--params/--set)"
                                                     if count else ""))
    data["device"], device_lines = device.info(robot)  # stops, friction, motor, encoder
    lines += ["", *device_lines]
    show(args, data, "\n".join(lines))
    return 0


def _gimbal_info(robot: Phantom, gimbal: Gimbal) -> tuple[dict[str, Any], list[str]]:
    """info's data and lines of the stylus gimbal ``gimbal`` of ``robot``."""
    data = {"joints": list(robot.gimbal_joints), "lower": list(gimbal.lower), "upper": list(gimbal.upper),
            "tip_offset": gimbal.tip_offset, "locked_at": list(gimbal.locked_at)}
    ranges = ", ".join(f"{j} {lo:.3f}..{hi:.3f}" for j, lo, hi in zip(robot.gimbal_joints, gimbal.lower, gimbal.upper))
    lines = ["", f"stylus gimbal (passive; OpenHaptics' raw gimbal angles) [rad]: {ranges}; tip "
                 f"{gimbal.tip_offset} m along the stylus's -z; the arm's dynamics hold it at "
                 f"{list(gimbal.locked_at)} rad",
             f"  source: {robot.config.sources['gimbal']}"]
    return data, lines




def check(args: argparse.Namespace) -> int:
    """phantom_pin.dynamics.verification.check(), printed: exit code 1 when a comparison fails."""
    bar = Progress("check", args.n, enabled=False if args.quiet else None)
    try:
        report = verification.check(phantom(args), args.n, args.seed, progress=bar.update)
    finally:
        bar.close()
    text = [f"{args.n} random states (seed {args.seed}) inside the joint limits",
            f"{'check':60} {'max error':>10} {'tolerance':>10}"]
    text += [f"{r.check:60} {r.max_error:10.2e} {r.tolerance:10.0e}" if r.max_error is not None
             else f"{r.check:60} {'n/a':>10}  (parameters are not the report's)" for r in report.rows]
    text.append("all checks pass" if report.passed else "FAIL")
    show(args, report.as_dict(), "\n".join(text))
    return 0 if report.passed else 1


def fk(args: argparse.Namespace) -> int:
    """g_st at --theta, with a warning outside the joint limits; with --gimbal the stylus's pose
    and its tip's too."""
    robot = phantom(args)
    poses = {"g_st": robot.forward_kinematics(args.theta)}
    if args.gimbal is not None:
        poses |= {"stylus": robot.stylus_pose(args.theta, args.gimbal),
                  "stylus_tip": robot.stylus_tip_pose(args.theta, args.gimbal)}
    warn_limits(args.theta, robot.model.lowerPositionLimit, robot.model.upperPositionLimit)
    warn_gimbal(args.gimbal, robot)
    names = {"g_st": "tip", "stylus": "stylus frame (the gimbal centre)", "stylus_tip": "stylus tip"}
    show(args, {k: g.tolist() for k, g in poses.items()},
         "\n".join(f"{names[k]} position in s [m]: {np.array2string(g[:3, 3], precision=6)}\n"
                   f"{'g_st' if k == 'g_st' else 'g_s,' + k} =\n{np.array2string(g, precision=6, suppress_small=True)}"
                   for k, g in poses.items()))
    return 0


def ik(args: argparse.Namespace) -> int:
    """The theta that puts the tip at a position of frame s."""
    robot = phantom(args)
    theta = robot.inverse_kinematics(args.position, branch=args.branch)
    warn_limits(theta, robot.model.lowerPositionLimit, robot.model.upperPositionLimit, "the solution theta")
    show(args, {"theta": theta.tolist()}, f"theta [rad]: {np.array2string(theta, precision=9)}")
    return 0


def dynamics(args: argparse.Namespace) -> int:
    """M, C, N and tau at one state (the gimbal held at --gimbal's angles, or at locked_at)."""
    robot = phantom(args)
    results = {"M": robot.mass_matrix(args.theta, args.gimbal),
               "C": robot.coriolis_matrix(args.theta, args.dtheta, args.gimbal),
               "N": robot.gravity(args.theta, args.gimbal),
               "tau": robot.inverse_dynamics(args.theta, args.dtheta, args.ddtheta, args.gimbal)}
    warn_limits(args.theta, robot.model.lowerPositionLimit, robot.model.upperPositionLimit)
    warn_gimbal(args.gimbal, robot)
    text = "\n".join(f"{k} =\n{np.array2string(v, precision=6)}" for k, v in results.items())
    show(args, {k: v.tolist() for k, v in results.items()}, text)
    return 0


def write(args: argparse.Namespace) -> int:
    """urdf, srdf, mjcf, links: the files of describe(--model or --config, --prefix, --params and --set)."""
    target = output(args)
    scene = output(args, "--scene") if args.kind == "mjcf" and args.scene is not None else None
    if scene is not None and scene.resolve() == target.resolve():
        raise PhantomPinError(f"{scene} is the --output file; the scene includes the model, give it its own file",
                              argument="--scene")
    # the scene includes the model by a path relative to the scene's own folder (MuJoCo resolves it there)
    robot_file = target.name if scene is None else os.path.relpath(target.resolve(), scene.resolve().parent)
    made = description(args, prefix=args.prefix, robot_file=robot_file)
    if args.kind == "urdf" and args.convention == "driver":
        write_text(target, driver_urdf(made.config.folder if made.model is None else made.config.name,
                                       prefix=args.prefix, overrides=overrides(args)))
        print(f"wrote {target}")
        return 0
    texts = {"urdf": made.urdf, "srdf": made.srdf, "mjcf": made.mjcf, "links": links_yaml(made.config)}
    # both files or neither (a scene that cannot be written leaves no model behind)
    write_texts([(target, texts[args.kind], "--output")] + ([] if scene is None else [(scene, made.scene, "--scene")]))
    print(f"wrote {target}")
    if scene is not None:
        print(f"wrote {scene}")
    return 0


def _read_motion(path: Path) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """(t (N,) s, theta (N, 3) rad, gimbal (N, 3) rad or None) of show's --trajectory file: a
    CSV in the dialects identify reads, with the columns MOTION_COLUMNS and, optionally, all of
    GIMBAL_COLUMNS; PhantomPinError naming --trajectory otherwise (some gimbal columns but not
    all, times not strictly increasing, fewer than two rows)."""
    try:
        try:
            _, column = io._read_table(path, MOTION_COLUMNS + GIMBAL_COLUMNS)
            gimbal = np.column_stack([column[name] for name in GIMBAL_COLUMNS])
        except LogError as error:
            lines, column = io._read_table(path, MOTION_COLUMNS)  # the file's own error, if it has one
            if "gimbal" in lines[0][1].lower():
                raise error from None  # some of the gimbal's columns, not all, or one twice
            gimbal = None
    except LogError as error:
        raise PhantomPinError(error.detail, argument="--trajectory") from None
    t = column["t"]
    if len(t) < 2 or not (np.diff(t) > 0).all():
        raise PhantomPinError(f"{path}: expected two rows or more, times t (s) strictly increasing",
                              argument="--trajectory")
    return t, np.column_stack([column[name] for name in MOTION_COLUMNS[1:]]), gimbal


def _warn_motion(t: np.ndarray, angles: np.ndarray, lower: np.ndarray, upper: np.ndarray, what: str) -> None:
    """One warning line on stderr if some of ``angles`` (N, 3) rad at ``t`` (s) are outside
    the box limits: how many, and the first."""
    outside = np.flatnonzero(~within_box(angles, lower, upper))
    if outside.size:
        first = outside[0]
        warn(f"--trajectory: {what} is outside the joint limits {vector(lower, '{:.6g}')}..{vector(upper, '{:.6g}')}"
             f" rad at {outside.size} of {len(t)} samples, first at t = {t[first]:.6g} s: "
             f"{vector(angles[first], '{:.6g}')} rad (shown anyway)")


def _motion(args: argparse.Namespace, robot: Any) -> tuple[np.ndarray, np.ndarray, object]:
    """(times, theta, gimbal) that show plays for --trajectory: the file's gimbal columns, or
    --gimbal held throughout (None: zero); samples outside the limits warned about."""
    if args.theta is not None:
        raise PhantomPinError("--trajectory gives the postures; give one or the other", argument="--theta")
    t, theta, gimbal = _read_motion(args.trajectory)
    lower, upper = robot.model.lowerPositionLimit, robot.model.upperPositionLimit  # the arm's, then a gimbal's
    _warn_motion(t, theta, lower[:3], upper[:3], "theta")
    if gimbal is None:
        return t, theta, args.gimbal
    if robot.model.nq == 3:
        raise PhantomPinError(f"{args.trajectory} has gimbal columns, but this model has no stylus gimbal",
                              argument="--trajectory")
    if args.gimbal is not None:
        raise PhantomPinError("the --trajectory file's gimbal columns give the gimbal's angles; give one or the other",
                              argument="--gimbal")
    _warn_motion(t, gimbal, lower[3:], upper[3:], "gimbal")
    return t, theta, gimbal


def show_command(args: argparse.Namespace) -> int:
    """The arm in meshcat: a live viewer on 127.0.0.1 until Ctrl-C, or --html FILE; a posture,
    or the motion of --trajectory."""
    from phantom_pin.viewer import Viewer  # meshcat is only needed here

    if args.html is not None:
        output(args, "--html")
    robot = load(description(args))
    motion = None if args.trajectory is None else _motion(args, robot)
    lower, upper = robot.model.lowerPositionLimit, robot.model.upperPositionLimit  # the arm's, then a gimbal's
    if args.theta is not None:
        warn_limits(args.theta, lower[:3], upper[:3])
    if args.gimbal is not None and robot.model.nq == 6:
        warn_limits(args.gimbal, lower[3:], upper[3:], "gimbal")
    with Viewer(robot) as viewer:
        if args.tip_force is not None:
            viewer.set_force(args.tip_force)
        if motion is None:
            viewer.show(robot.q0[:3] if args.theta is None else args.theta, args.gimbal)
        else:
            times, theta, gimbal = motion
            viewer.animate(times, theta, gimbal=gimbal)
        if args.html is not None:
            print(f"wrote {viewer.export_html(args.html, force=args.force)}")
            return 0
        with viewer.stop_on_signals():  # from before the URL is printed to after the server stopped
            try:
                print(f"meshcat viewer at {viewer.url} (Ctrl-C to stop)", flush=True)
                if args.open:
                    webbrowser.open(viewer.url)
                viewer.wait()
            finally:
                viewer.close()
    return 0


def add_parsers(sub: argparse._SubParsersAction) -> None:
    """info, check, fk, ik, dynamics, urdf, srdf, mjcf, links and show."""
    command = sub.add_parser("info", help="joints, limits, links with mass, COM and inertia, rotor data, "
                                          "the device's stops, friction, motor and encoder with sources")
    command.set_defaults(run=info)
    command.add_argument("--json", action="store_true", help="print JSON")
    command = sub.add_parser("check", help="Phantom vs closed form vs the appendix at N random states")
    command.add_argument("-n", type=positive_integer, default=1000,
                         help=f"number of random states, e.g. 1000 or 1e6 (default 1000; evaluated "
                              f"{verification.CHUNK} at a time, at most {verification.MAX_STATES:.0e})")
    command.add_argument("--seed", type=int, default=0)
    command.add_argument("--json", action="store_true", help="print JSON")
    command.set_defaults(run=check, options={"states": "-n", "phantom": "--model"})
    command = sub.add_parser("fk", help="g_st (eq. 10) at theta (rad)")
    command.add_argument("theta", metavar="T", **THREE)
    add_gimbal(command, "also the stylus frame's pose and its tip's")
    command.add_argument("--json", action="store_true", help="print JSON")
    command.set_defaults(run=fk, options={"gimbal": "--gimbal"})
    command = sub.add_parser("ik", help="theta (rad) that puts the tip at X Y Z (m, frame s)")
    command.add_argument("position", metavar="P", **THREE)
    command.add_argument("--branch", choices=["report", "other"], default="report")
    command.add_argument("--json", action="store_true", help="print JSON")
    command.set_defaults(run=ik)
    command = sub.add_parser("dynamics", help="M, C, N and tau at a state")
    command.add_argument("--theta", required=True, **THREE)
    command.add_argument("--dtheta", default=[0.0, 0.0, 0.0], **THREE)
    command.add_argument("--ddtheta", default=[0.0, 0.0, 0.0], **THREE)
    add_gimbal(command, "held there (default: the configuration's locked_at)")
    command.add_argument("--json", action="store_true", help="print JSON")
    command.set_defaults(run=dynamics, options={"gimbal": "--gimbal"})
    for kind in ("urdf", "srdf", "mjcf", "links"):
        command = sub.add_parser(kind, help=f"write the {kind.upper()} generated from --model or --config"
                                 if kind != "links" else "write the links in full (mass, COM, inertia; the "
                                 "xacro's links_file) of --model or --config")
        command.add_argument("--output", "-o", required=True, action=Once)
        command.add_argument("--prefix", default="")
        command.add_argument("--force", "-f", action="store_true", help="overwrite an existing file")
        command.set_defaults(kind=kind, run=write, options={"prefix": "--prefix"})
        if kind == "urdf":
            command.add_argument("--convention", choices=CONVENTIONS, default="report",
                                 help="joint names: report (joint1..3 = theta, the default) or driver "
                                      "(the ROS drivers' waist, shoulder, elbow = theta3 - theta2, yaw, pitch, roll)")
        if kind == "mjcf":
            command.add_argument("--scene", help="also write a scene (floor, light, table) that "
                                                 "includes the MJCF of --output (same folder)")
    command = sub.add_parser("show", help="the arm in meshcat: a live viewer on 127.0.0.1, or --html FILE")
    command.add_argument("--theta", metavar="T", help="posture (rad; default: the SRDF's resting)", **THREE)
    command.add_argument("--tip-force", metavar="F", help="force on the tip (N, frame s), drawn as an arrow",
                         **THREE)
    command.add_argument("--gimbal", metavar="G", help="a stylus gimbal's angles (rad, OpenHaptics' raw "
                                                       "gimbal angles; the Touch; default 0)", **THREE)
    command.add_argument("--trajectory", type=Path, metavar="FILE",
                         help="play a motion: a CSV with the columns t, theta1, theta2, theta3 (s, rad; "
                              "simulate's output, a log and excite's trajectory have them) and, for a stylus "
                              "gimbal, gimbal1, gimbal2, gimbal3 (rad, OpenHaptics' raw gimbal angles; "
                              "without them, --gimbal is held)")
    command.add_argument("--html", help="write a self-contained HTML file instead of serving")
    command.add_argument("--force", "-f", action="store_true", help="overwrite an existing --html file")
    command.add_argument("--open", action="store_true", help="open the live viewer in a browser")
    command.set_defaults(run=show_command, options={"gimbal": "--gimbal"})
