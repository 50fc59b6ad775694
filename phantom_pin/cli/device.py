"""The device's commands of ``phantom-pin``: ``simulate``, and the device data of ``info``."""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np

from phantom_pin._progress import Progress
from phantom_pin._validation import fixed_rate
from phantom_pin.cli.common import (
    Once,
    add_gimbal,
    add_plot_option,
    check_record,
    csv_text,
    emit,
    output,
    phantom,
    plot_target,
    warn,
    warn_gimbal,
    write_texts,
)
from phantom_pin.device.controllers import KD, KP, tracking
from phantom_pin.device.device import Device
from phantom_pin.device.simulation import SimulationResult, simulate
from phantom_pin.dynamics.phantom import Phantom
from phantom_pin.exceptions import PhantomPinError
from phantom_pin.identification.data import io
from phantom_pin.viewer import plots

#: simulate()'s arguments that are options of the command (its errors name them).
OPTIONS = {name: "--" + name for name in ("theta0", "dtheta0", "duration", "rate", "quantization", "gimbal")} | {
    "device": "the model (--model, --config, --params, --set)", "path": "--trajectory"}
#: Columns of the result, with their units, as written to JSON and CSV.
UNITS = {"t": "s", "theta": "rad", "dtheta": "rad/s", "tau": "N m (applied, held until the next sample)",
         "tau_commanded": "N m", "current": "A", "tip": "m (frame s)"}
#: simulate()'s arguments that --trajectory sets, with what of the file they are.
TRAJECTORY_SETS = {"theta0": "its first state:", "dtheta0": "its first rates:", "duration": "its duration:",
                   "rate": "its rate:"}
#: Share of samples with a clipped command above which simulate warns (a tracking run that
#: saturates this often follows nothing).
SATURATED_SHARE = 0.1
#: The output formats, by the file's extension.
FORMATS = {".json": "json", ".csv": "csv"}


def add_parsers(sub: argparse._SubParsersAction) -> None:
    """``phantom-pin simulate``."""
    three = {"nargs": 3, "type": float}
    command = sub.add_parser("simulate", help="a controller sampled at --rate driving the device "
                                              "(friction, stops, saturation), as JSON or CSV")
    command.set_defaults(run=simulate_command, options=OPTIONS)
    command.add_argument("--theta0", metavar="T", help="initial posture (rad); required without --trajectory",
                         **three)
    command.add_argument("--dtheta0", metavar="W", help="initial rates (rad/s, default 0 0 0)", **three)
    command.add_argument("--duration", type=float, help="simulated time (s); required without --trajectory")
    command.add_argument("--trajectory", type=Path,
                         help="track excite's CSV: its torque as feed-forward plus PD "
                              f"({KP:g} N m/rad, {KD:g} N m s/rad), from its first state, "
                              "at its rate, for its duration; the CSV output is a log that identify reads")
    command.add_argument("--convention", choices=["report", "openhaptics"],
                         help="the --trajectory file's columns: the report's theta (rad) and N m (default), or "
                              "OpenHaptics' joint angles (rad) and joint torques (mN m), as excite writes "
                              "them with --convention openhaptics; the output is in the report's terms")
    command.add_argument("--rate", type=float, help="controller rate (Hz, default 1000)")
    command.add_argument("--controller", choices=["none", "gravity"],
                         help="zero torque (default), or gravity compensation N(theta) from the Phantom")
    command.add_argument("--no-friction", action="store_true", help="no joint friction (viscous and Coulomb)")
    command.add_argument("--no-hard-stops", action="store_true", help="no stops (the joints turn freely)")
    clip = command.add_mutually_exclusive_group()
    clip.add_argument("--no-saturation", action="store_true", help="apply commands unclipped")
    clip.add_argument("--saturation", choices=("continuous", "peak"),
                      help="clip commands at the motors' continuous or peak torque (default: actuation.yaml's "
                           "saturation, as the MJCF)")
    add_gimbal(command, "held there during the run (default: the configuration's locked_at)")
    command.add_argument("--quantization", action="store_true",
                         help="the controller sees the angles rounded to encoder counts (rad) and their backward "
                              "difference")
    command.add_argument("--format", choices=["json", "csv"],
                         help="output format (default: the --output file's extension, .json or .csv; json on "
                              "standard output)")
    command.add_argument("--output", "-o", action=Once, help="file to write (default: standard output)")
    command.add_argument("--force", "-f", action="store_true", help="overwrite an existing --output or --plot file")
    add_plot_option(command, "the angles, rates and torques over time with the stops and the saturation")


def _format(args: argparse.Namespace) -> str:
    """The output format: --format, else the --output file's extension, else json; a
    mismatch between the two is refused before the run."""
    if args.output is None:
        return args.format or "json"
    by_extension = FORMATS.get(Path(args.output).suffix.lower())
    if args.format is None:
        if by_extension is None:
            raise PhantomPinError(f"{args.output} has no .json or .csv extension; give --format json or csv",
                                  argument="--output")
        return by_extension
    if by_extension is not None and by_extension != args.format:
        raise PhantomPinError(f"{args.format} into {args.output}, a {Path(args.output).suffix} file; give one "
                              f"format", argument="--format")
    return args.format


@dataclasses.dataclass(frozen=True)
class _Run:
    """What one simulate command runs: its start (rad, rad/s), duration (s), rate (Hz) and controller."""

    theta0: list[float]
    dtheta0: list[float]
    duration: float
    rate: float
    controller: Callable[[float, np.ndarray, np.ndarray], object] | None


def _tracking(args: argparse.Namespace) -> _Run:
    """The controller, start and timing that follow --trajectory: feed-forward plus PD."""
    for name in ("theta0", "dtheta0", "duration", "rate"):
        if getattr(args, name) is not None:
            raise PhantomPinError("--trajectory sets it (its first state, its duration and its rate)",
                                  argument="--" + name)
    if args.controller is not None:
        raise PhantomPinError("--trajectory is the controller", argument="--controller")
    t, theta, dtheta, _, tau = io.read_trajectory(args.trajectory, args.convention or "report")
    return _Run(theta[0].tolist(), dtheta[0].tolist(), float(t[-1] - t[0]), fixed_rate(t),
                tracking(t, theta, dtheta, tau))


def _free(args: argparse.Namespace, robot: Phantom) -> _Run:
    """The start, timing and controller of --theta0, --dtheta0, --duration, --rate and --controller."""
    if args.convention is not None:
        raise PhantomPinError("it reads --trajectory; give one", argument="--convention")
    for name in ("theta0", "duration"):
        if getattr(args, name) is None:
            raise PhantomPinError(f"required: --{name} (or --trajectory)", argument="--" + name)
    controller = None
    if args.controller == "gravity":
        def controller(t: float, theta: np.ndarray, dtheta: np.ndarray) -> np.ndarray:
            return robot.gravity(theta, args.gimbal)
    return _Run(args.theta0, [0.0, 0.0, 0.0] if args.dtheta0 is None else args.dtheta0, args.duration,
                1000.0 if args.rate is None else args.rate, controller)


def simulate_command(args: argparse.Namespace) -> int:
    """Run ``phantom-pin simulate``: nothing is written unless the simulation succeeds."""
    target = None if args.output is None else output(args)
    form = _format(args)
    plot = plot_target(args)
    robot = phantom(args)
    device = Device(robot)
    if args.trajectory is not None:
        check_record(args.trajectory, robot.config.name, args.convention or "report", "--trajectory")
    run = _tracking(args) if args.trajectory is not None else _free(args, robot)
    result = _simulated(args, run, device)
    _warn_run(args, run, result, device)
    settings = _settings(args, run, result, device)
    text = _json(result, settings) if form == "json" else _csv(result, robot.config.name)
    page = None if plot is None else _plot(result, settings, device, robot.config.name)
    _write(target, text, plot, page, len(result.t))
    return 0


def _simulated(args: argparse.Namespace, run: _Run, device: Device) -> SimulationResult:
    """simulate() on ``run`` with the command's options, an error of what --trajectory sets
    named as the file's."""
    bar = Progress("simulate", 1.0, enabled=False if args.quiet else None)
    try:
        return simulate(run.theta0, run.duration, run.controller, dtheta0=run.dtheta0, rate=run.rate,
                        friction=not args.no_friction, hard_stops=not args.no_hard_stops,
                        saturation=False if args.no_saturation else args.saturation or True,
                        quantization=args.quantization, device=device, progress=bar.update, gimbal=args.gimbal)
    except PhantomPinError as error:  # what --trajectory sets is the file's, not an option's
        if args.trajectory is None or error.argument not in TRAJECTORY_SETS:
            raise
        raise PhantomPinError(f"{args.trajectory}: {TRAJECTORY_SETS[error.argument]} {error.detail}",
                              argument="--trajectory") from None
    finally:
        bar.close()


def _warn_run(args: argparse.Namespace, run: _Run, result: SimulationResult, device: Device) -> None:
    """The run's warnings: torques clipped, the gimbal's angles, a start beyond the stops."""
    saturated = float(np.mean(np.any(result.tau != result.tau_commanded, axis=1)))
    if saturated > SATURATED_SHARE:
        hint = (" (is the file in OpenHaptics' mN m? --convention openhaptics)"
                if args.trajectory is not None and args.convention is None else "")
        warn(f"{100 * saturated:.1f} % of the commanded torques exceeded the saturation and were clipped{hint}")
    warn_gimbal(args.gimbal, device.phantom)
    if not args.no_hard_stops and not device.within_limits(run.theta0):  # after the run: a refused one alone
        warn(f"--theta0 {run.theta0} rad starts beyond the stops, which push it back")


def _settings(args: argparse.Namespace, run: _Run, result: SimulationResult, device: Device) -> dict:
    """The run's settings as the JSON output and the plot's facts give them."""
    settings = dataclasses.asdict(run) | {key: getattr(args, key) for key in (
        "controller", "no_friction", "no_hard_stops", "no_saturation", "saturation", "quantization", "gimbal")}
    settings["controller"] = args.controller or "none"
    settings["saturation"] = False if args.no_saturation else args.saturation or device.config.actuation.saturation
    settings["substeps"] = result.substeps
    settings["trajectory"] = None if args.trajectory is None else str(args.trajectory)
    settings["model"] = device.phantom.config.name
    return settings


def _write(target: Path | None, text: str, plot: Path | None, page: str | None, samples: int) -> None:
    """Every file or none: the output (else on stdout) and the plot, each reported."""
    staged = ([] if target is None else [(target, text, "--output")]) + (
        [] if plot is None or page is None else [(plot, page, "--plot")])
    write_texts(staged)                                   # every file or none
    if target is None:
        emit(text)
    else:
        print(f"wrote {target} ({samples} samples)")
    if plot is not None and page is not None:
        print(f"wrote {plot}", file=sys.stderr if target is None else sys.stdout)


def _plot(result: SimulationResult, settings: dict, device: Device, name: str) -> str:
    """The --plot page of a run: angles with the stops, rates, applied (and commanded) torques
    with the saturation's limits (none with --no-saturation)."""
    limits, policy = device.config.limits.stops, settings["saturation"]
    stops = (np.array(limits.lower), np.array(limits.upper), limits.coupled.theta2_minus_theta3_max,
             limits.coupled.theta3_minus_theta2_max)
    torque_limit = None if policy is False else np.array(device.config.actuation.limit(policy))
    facts = [("model", name), ("controller", settings["controller"]),
             ("start", f"θ0 {settings['theta0']} rad, θ̇0 {settings['dtheta0']} rad/s"),
             ("duration, rate", f"{settings['duration']:g} s, {settings['rate']:g} Hz ({len(result.t)} samples)"),
             ("friction, stops", f"{'off' if settings['no_friction'] else 'on'}, "
                                 f"{'off (drawn anyway)' if settings['no_hard_stops'] else 'on'}"),
             ("saturation", "off" if policy is False else f"{policy} torque, drawn as the torque limits"),
             ("trajectory", settings["trajectory"] or "none")]
    return plots.run_page(f"phantom-pin simulate: {name}", facts, result.t, result.theta, result.dtheta,
                          result.tau, stops, torque_limit, f"saturation ({policy})", result.tau_commanded)


def _columns(result: SimulationResult) -> dict[str, str]:
    """The result's columns with their units: UNITS, without ``current`` for a model
    without public motor data."""
    return {name: unit for name, unit in UNITS.items() if getattr(result, name) is not None}


def _json(result: SimulationResult, settings: dict) -> str:
    columns = _columns(result)
    data = {"settings": settings, "units": columns}
    data.update({name: getattr(result, name).tolist() for name in columns})
    return json.dumps(data) + "\n"


def _csv(result: SimulationResult, model: str) -> str:
    """The run as a log that identify reads: the report's convention, the model recorded."""
    header, columns = [], []
    for name, unit in _columns(result).items():
        values = getattr(result, name).reshape(len(result.t), -1)
        suffixes = [""] if values.shape[1] == 1 else (["_x", "_y", "_z"] if name == "tip" else ["1", "2", "3"])
        header += [f"{name}{s} [{unit.split(' (')[0]}]" for s in suffixes]
        columns.append(values)
    return csv_text(header, np.hstack(columns), model, "report")


def info(phantom: Phantom) -> tuple[dict, list[str]]:
    """The device data of ``phantom-pin info``, as (JSON data, text lines), with sources."""
    device = Device(phantom)
    config = device.config
    stops, friction, motor, encoder = (config.limits.stops, config.actuation.friction, config.actuation.motor,
                                       config.actuation.encoder)
    sections = {"stops": dataclasses.asdict(stops), "friction": dataclasses.asdict(friction)}
    deg = 180 / math.pi
    vector = " ".join
    text = {
        "stops": "stops [deg]: " + ", ".join(f"joint{i + 1} {lo * deg:.1f}..{hi * deg:.1f}"
                                             for i, (lo, hi) in enumerate(zip(stops.lower, stops.upper)))
        + f"; theta2 - theta3 <= {stops.coupled.theta2_minus_theta3_max * deg:.1f}, theta3 - theta2 <= "
          f"{stops.coupled.theta3_minus_theta2_max * deg:.1f}; K {stops.stiffness:g} N m/rad, "
          f"B {stops.damping:g} N m s/rad",
        "friction": (f"friction: viscous {friction.viscous[0]:g} N m s/rad + coulomb {friction.coulomb[0]:g} N m * "
                     "sign(dtheta) in motion; at rest a joint sticks below the Coulomb torque") if friction.uniform else
                    (f"friction per joint: viscous [{vector(f'{x:g}' for x in friction.viscous)}] N m s/rad + coulomb "
                     f"[{vector(f'{x:g}' for x in friction.coulomb)}] N m * sign(dtheta) in motion; at rest a joint "
                     "sticks below its Coulomb torque"),
    }
    if motor is None:
        # what the model lacks, said instead of invented (its sources say why)
        sections["motor"] = {"public": False, "peak_joint_torque": device.peak_torque.tolist()}
        text["motor"] = (f"motor: none public; joint torque limits [{vector(f'{x:.4f}' for x in device.peak_torque)}] "
                         f"N m (joint_torque_limit); no currents, no armature")
    else:
        sections["motor"] = dataclasses.asdict(motor) | {"continuous_joint_torque": device.continuous_torque.tolist(),
                                                         "peak_joint_torque": device.peak_torque.tolist()}
        text["motor"] = (f"motor: continuous {motor.max_continuous_torque * 1e3:g} mN m / "
                         f"{motor.max_continuous_current:g} A, stall {motor.stall_torque * 1e3:g} mN m / "
                         f"{motor.stall_current:g} A, Kt {motor.torque_constant * 1e3:g} mN m/A, R "
                         f"{motor.terminal_resistance:g} Ohm, no-load {motor.max_speed:.1f} rad/s; at the joints: "
                         f"continuous [{vector(f'{x:.4f}' for x in device.continuous_torque)}] N m, peak "
                         f"[{vector(f'{x:.4f}' for x in device.peak_torque)}] N m")
    if encoder is None:
        sections["encoder"] = {"public": False}
        text["encoder"] = "encoder: none public; no counts, no quantization"
    else:
        sections["encoder"] = dataclasses.asdict(encoder) | {"resolution": device.encoder_resolution.tolist()}
        text["encoder"] = (f"encoder: {encoder.cycles_per_revolution:g} cycles/rev x {encoder.counts_per_cycle:g} "
                           f"counts/cycle on the motor; resolution "
                           f"[{vector(f'{x:.3e}' for x in device.encoder_resolution)}] rad at the joints")
    if device.ratios is None:
        sections["transmission_ratio"] = {"public": False}
        text["transmission_ratio"] = "transmission ratios: none public"
    else:
        sections["transmission_ratio"] = {"ratios": device.ratios.tolist()}
        text["transmission_ratio"] = f"transmission ratios: [{vector(f'{x:g}' for x in device.ratios)}]"
    for name, section in sections.items():
        section["source"] = config.sources[name]
    lines = ["device (phantom_pin.Device), SI units at the joints unless said:"]
    for name, section in sections.items():
        lines += [text[name], f"  source: {section['source']}"]
    return sections, lines
