"""The identification's commands of ``phantom-pin``: excite and identify."""

from __future__ import annotations

import argparse
import inspect
import math
from pathlib import Path

import numpy as np

from phantom_pin._progress import Progress
from phantom_pin.cli.common import (
    Once,
    add_plot_option,
    check_record,
    csv_text,
    description,
    output,
    overrides,
    plot_target,
    warn,
    write_texts,
)
from phantom_pin.config import DEFAULT
from phantom_pin.description.build import Description, held
from phantom_pin.dynamics.phantom import Phantom
from phantom_pin.exceptions import PhantomPinError
from phantom_pin.identification import (
    MIN_SPEEDS,
    TRAJECTORY_COLUMNS,
    Excitation,
    Identification,
    Recording,
    RefusedError,
    Rest,
    continuous_effort,
    delay_argument,
    estimate_gravity,
    gravity_overlay,
    identify,
    is_bag,
    optimise,
    read_bag,
    read_log,
    read_postures,
    read_trajectory,
    refusal,
    report_page,
    rest_of,
    stylus_keys,
)
from phantom_pin.interfaces import conventions, profiles
from phantom_pin.viewer import plots

#: The conventions of the CSV columns (phantom_pin.interfaces.conventions).
CONVENTIONS = ("report", "openhaptics")
#: Fewest samples per cycle of the excitation's highest harmonic that excite writes.
MIN_SAMPLES_PER_HARMONIC = 20
#: Most rows excite writes (13 columns of 8 bytes each in memory: 0.2 GB).
MAX_ROWS = 2_000_000
#: The excitation periods excite accepts (s).
PERIOD_RANGE = (0.5, 600.0)


def _periods(duration: float, period: float) -> int:
    """Whole periods covering ``duration`` (s), at least one."""
    return max(1, math.ceil(duration / period - 1e-9))


def _suffix(path: Path, suffixes: tuple[str, ...], kind: str) -> None:
    """--output ends with one of ``suffixes``: the command writes ``kind`` only."""
    if path.suffix.lower() not in suffixes:
        raise PhantomPinError(f"{path}: this command writes {kind}; name a {' or '.join(suffixes)} file",
                              argument="--output")


#: The defaults of the library's identify() and optimise(), the commands' own (one place each).
IDENTIFY = {name: p.default for name, p in inspect.signature(identify).parameters.items() if p.default is not p.empty}
OPTIMISE = {name: p.default for name, p in inspect.signature(optimise).parameters.items() if p.default is not p.empty}
#: The options of the trajectory fit, which rest postures do not take (dest, option, default):
#: identify()'s defaults (--fixed-gains: not its gains).
TRAJECTORY_ONLY = (("structure", "--structure", IDENTIFY["structure"]), ("delay", "--delay", IDENTIFY["delay"]),
                   ("fixed_gains", "--fixed-gains", not IDENTIFY["gains"]),
                   ("torque_timing", "--torque-timing", IDENTIFY["timing"]),
                   ("min_speed", "--min-speed", IDENTIFY["min_speed"]), ("cutoff", "--cutoff", IDENTIFY["cutoff"]),
                   ("accept", "--accept", IDENTIFY["accept"]), ("report", "--report", None),
                   ("reference", "--reference", IDENTIFY["reference"]))


def _static_command(args: argparse.Namespace, phantom: Phantom, recording: Recording | None,
                    given: dict[str, object]) -> int:
    """identify --static: gravity from rest postures (estimate_gravity), written as an overlay of
    the rigid body (gravity_overlay: friction as given, rest says nothing of it)."""
    for dest, option, default in TRAJECTORY_ONLY:
        if getattr(args, dest) != default:
            raise PhantomPinError("fits a trajectory: --static fits rest postures (gravity) only", argument=option)
    if recording is not None:
        rest = rest_of(recording.log)
    else:
        table = read_postures(args.log)
        rest = rest_of(read_log(args.log, args.convention)) if table is None else Rest(*table)
    gravity = estimate_gravity(rest, phantom, args.prior_spread)
    lines = [*([] if recording is None else recording.lines()), *gravity.lines(len(rest.theta))]
    text = gravity_overlay(gravity, phantom, given, args.log.name, lines)
    for line in lines:
        print(line)
    write_texts([(args.output, text, "--output")])
    print(f"wrote {args.output}")
    return 0


def _recording(args: argparse.Namespace) -> Recording | None:
    """The bag LOG names (its driver profile's JointState: read_bag), or None for a CSV log."""
    if not is_bag(args.log):
        if args.driver is not None or args.topic is not None:
            raise PhantomPinError(f"{args.log} is a CSV log, not a rosbag2 recording: --driver and --topic read bags",
                                  argument="--driver" if args.driver is not None else "--topic")
        return None
    if args.convention != "report":
        raise PhantomPinError("a bag's conventions are its driver profile's (--driver)", argument="--convention")
    return read_bag(args.log, args.driver, args.topic)


def _reference(path: Path | None, model: str, convention: str) -> tuple[np.ndarray, np.ndarray] | None:
    """--reference's trajectory (excite's CSV for ``model``, in the log's ``convention``, as excite
    --convention writes it): its times (s) and angles in the report's theta (rad), or None; a file
    that is not one is refused naming --reference."""
    if path is None:
        return None
    check_record(path, model, convention, "--reference")
    try:
        t, theta = read_trajectory(path, convention)[:2]
    except PhantomPinError as error:
        raise PhantomPinError(error.detail, argument="--reference") from None
    return t, theta


def _delay(text: str | None) -> float | None:
    """--delay's seconds (None: estimate it), checked by delay_argument."""
    if text is None:
        return None
    try:
        value = float(text)
    except ValueError:
        raise PhantomPinError(f"expected seconds (a number such as 0.001), got {text!r}", argument="--delay") from None
    return delay_argument(value)


def add_parsers(sub: argparse._SubParsersAction) -> None:
    """Add the excite and identify subcommands to the phantom-pin parser."""
    _add_excite(sub)
    _add_identify(sub)


def _add_excite(sub: argparse._SubParsersAction) -> None:
    """excite's options, its defaults optimise()'s."""
    excite = sub.add_parser("excite", help="write an optimised excitation trajectory (CSV) inside the stops")
    excite.set_defaults(run=excite_command)
    excite.add_argument("--output", "-o", required=True, type=Path, action=Once)
    excite.add_argument("--duration", type=float, default=20.0,
                        help="seconds of trajectory, rounded up to whole periods (default 20)")
    excite.add_argument("--rate", type=float, default=1000.0, help="samples per second (default 1000)")
    excite.add_argument("--period", type=float, default=OPTIMISE["period"],
                        help=f"period of the Fourier series, s (default {OPTIMISE['period']:g})")
    excite.add_argument("--harmonics", type=int, default=OPTIMISE["harmonics"],
                        help=f"harmonics per joint (default {OPTIMISE['harmonics']})")
    excite.add_argument("--iterations", type=int, default=OPTIMISE["iterations"],
                        help=f"SLSQP iterations per start (default {OPTIMISE['iterations']})")
    excite.add_argument("--restarts", type=int, default=OPTIMISE["restarts"],
                        help=f"random starts (default {OPTIMISE['restarts']})")
    excite.add_argument("--seed", type=int, default=OPTIMISE["seed"])
    excite.add_argument("--force", "-f", action="store_true", help="overwrite an existing file")
    excite.add_argument("--convention", choices=CONVENTIONS, default="report",
                        help="columns in the report's theta (rad) and N m (default), or OpenHaptics' joint "
                             "angles (rad) and joint torques (mN m), for HD_CURRENT_JOINT_TORQUE")
    add_plot_option(excite, "the trajectory's angles, rates and torques (in the report's terms) with the stops and "
                            "the joint torque limits")


def _add_identify(sub: argparse._SubParsersAction) -> None:
    """identify's options, its defaults identify()'s."""
    identify = sub.add_parser("identify", help="identify the device's parameters from a log (CSV) "
                                               "into a --params overlay (YAML)")
    identify.set_defaults(run=identify_command, options={"path": "LOG", "cutoff": "--cutoff",
                                                         "prior_spread": "--prior-spread", "delay": "--delay",
                                                         "min_speed": "--min-speed", "reference": "--reference"})
    identify.add_argument("log", type=Path, help="CSV with the header t,theta1,theta2,theta3,tau1,tau2,tau3, or a "
                                                 "driver's rosbag2 recording (a folder, or its .mcap/.db3 file)")
    identify.add_argument("--driver", choices=profiles.names(), default=None,
                          help="the driver profile that recorded the bag (default: recognised by its joint names)")
    identify.add_argument("--topic", default=None,
                          help="the bag's sensor_msgs/JointState topic (default: the driver's, or the bag's only one)")
    identify.add_argument("--output", "-o", required=True, type=Path, action=Once)
    identify.add_argument("--cutoff", type=float, default=IDENTIFY["cutoff"],
                          help=f"low-pass cutoff in Hz (default {IDENTIFY['cutoff']:g})")
    identify.add_argument("--torque-timing", choices=("held", "sampled"), default=IDENTIFY["timing"],
                          help="held: each logged torque is a command applied until the next sample (a servo "
                               "loop's); sampled: the torque at that instant (a sensor, or a model); default: "
                               "chosen from the log on held-out quarters of it (held unless sampled fits them "
                               "better; docs/identification.md, step 4)")
    identify.add_argument("--min-speed", type=float, default=IDENTIFY["min_speed"], metavar="RAD_PER_S",
                          help="fit a joint's torques only where its rate stays above this over the filter's span "
                               "(near rest a joint sticks; default: chosen from the log of "
                               + ", ".join(f"{v:g}" for v in MIN_SPEEDS) + " rad/s on held-out quarters "
                               "of it, docs/identification.md, step 4)")
    identify.add_argument("--reference", type=Path, default=IDENTIFY["reference"], metavar="TRAJ.csv",
                          help="the trajectory the servo loop tracked (excite's CSV in the log's --convention, read "
                               "from the log's start): the log is a closed loop on it, identified with instrumental "
                               "variables against the noise the loop feeds back into the motion")
    identify.add_argument("--fixed-gains", action="store_true",
                          help="take the log's torques as they are (default: estimate each joint's torque gain "
                               "relative to joint 1, correct the model for it and report it)")
    identify.add_argument("--delay", default=IDENTIFY["delay"], metavar="SECONDS",
                          help="how long after the positions they belong to the torques were logged, s (default: "
                               "estimated from the log, between -5 and +5 ms); corrected for in the fit")
    identify.add_argument("--structure", choices=("general", "report"), default=IDENTIFY["structure"],
                          help="general: the rigid body in full, every identifiable base parameter (default); "
                               "report: the report's eight constants (a model in the report's form)")
    identify.add_argument("--prior-spread", type=float, default=IDENTIFY["prior_spread"],
                          help="how far the device may lie from the configuration you pass (the prior), as a "
                               "relative standard deviation of every physical parameter (default "
                               f"{IDENTIFY['prior_spread']:g}, at most 1e6); "
                               "what the log does not excite comes from the prior; inf: the log alone")
    identify.add_argument("--force", "-f", action="store_true", help="overwrite an existing --output file")
    identify.add_argument("--accept", action="store_true",
                          help="write the result even where the checks refuse it, each check's reason as a warning "
                               "and a comment in the file")
    identify.add_argument("--static", action="store_true",
                          help="gravity from rest: the log's or bag's stretches held still (0.5 s or more), or a "
                               "CSV of postures (theta1..3 rad, tau1..3 N m, no t column); the prior holds the rest")
    identify.add_argument("--report", type=Path, metavar="FILE.html", action=Once,
                          help="also write one self-contained HTML page of the fit (matplotlib's SVG, no script; "
                               "needs the plots extra): measured and predicted torques over time, the held-out "
                               "check, the torque left to friction and the residual against the rate, each "
                               "parameter with its uncertainty, the timing and gain findings, the warnings; "
                               "written with the overlay or not at all; --force overwrites it")
    identify.add_argument("--convention", choices=CONVENTIONS, default="report",
                          help="the log's theta and tau columns: the report's theta (rad) and N m (default), "
                               "or OpenHaptics' HD_CURRENT_JOINT_ANGLES (rad) and joint torques (mN m)")


def excite_command(args: argparse.Namespace) -> int:
    """phantom-pin excite, for the configuration of --model or --config (and the overrides)."""
    output(args)
    plot = plot_target(args)
    _check_excitation(args)
    periods = _periods(args.duration, args.period)
    rows = int(round(periods * args.period * args.rate)) + 1
    _suffix(args.output, (".csv",), "CSV")
    if not math.isclose(periods * args.period, args.duration, rel_tol=1e-9):
        warn(f"--duration {args.duration:g} s rounded up to {periods} whole period(s) of {args.period:g} s: "
             f"{periods * args.period:g} s (the excitation is periodic; --period sets its length)")
    made = description(args)
    phantom = Phantom(made)
    times = np.arange(rows) / args.rate
    bar = Progress("excite", 1.0, enabled=False if args.quiet else None)
    try:
        result = optimise(phantom, args.period, args.harmonics, iterations=args.iterations,
                                     restarts=args.restarts, seed=args.seed, times=times, progress=bar.update)
    except RuntimeError as error:
        raise PhantomPinError(str(error)) from None
    finally:
        bar.close()
    t = times
    theta, dtheta, ddtheta = result.trajectory(t)
    tau = phantom.inverse_dynamics(theta, dtheta, ddtheta) + made.config.actuation.friction.torque(dtheta)
    peak = np.abs(tau).max(axis=0)
    effort = continuous_effort(made)
    page = None if plot is None else _plot(args, made, result, (t, theta, dtheta, tau), effort)
    if args.convention == "openhaptics":  # a linear map: rates and accelerations as angles
        theta, dtheta, ddtheta = (conventions.openhaptics_from_theta(x) for x in (theta, dtheta, ddtheta))
        tau = conventions.openhaptics_torque_from_tau(tau)
    files = [(args.output, csv_text(list(TRAJECTORY_COLUMNS), np.column_stack([t, theta, dtheta, ddtheta, tau]),
                                    made.config.name, args.convention), "--output")]
    write_texts(files + ([] if plot is None or page is None else [(plot, page, "--plot")]))  # all or none
    if plot is not None and page is not None:
        print(f"wrote {plot}")
    print(f"wrote {args.output}: {periods} period(s) of {args.period:g} s at {args.rate:g} Hz, "
          f"{args.harmonics} harmonics per joint" + (", in OpenHaptics' joint angles (rad) and joint torques "
                                                    "(mN m)" if args.convention == "openhaptics" else ""))
    print(f"condition number of the general base regressor (columns scaled to unit norm): {result.condition:.3g}"
          + ("" if result.report_condition is None else
             f"; of the report structure's: {result.report_condition:.3g}"))
    print("peak torque [N m] (the model + its friction) / joint torque limit: "
          + ", ".join(f"{p:.3f}/{e:.3f}" for p, e in zip(peak, effort)))
    print(f"nearest approach to a stop: {result.min_slack:.3f} rad; the file starts and ends at rest")
    return 0


def _check_excitation(args: argparse.Namespace) -> None:
    """excite's numbers checked before any work: positive, enough samples per harmonic, the
    period in PERIOD_RANGE, at most MAX_ROWS rows."""
    for name in ("duration", "rate", "period"):
        value = getattr(args, name)
        if not (math.isfinite(value) and value > 0):
            raise PhantomPinError(f"expected a finite positive number, got {value!r}", argument=f"--{name}")
    for name, least in (("harmonics", 2), ("iterations", 1), ("restarts", 1), ("seed", 0)):
        if getattr(args, name) < least:
            raise PhantomPinError(f"expected an integer of at least {least}, got {getattr(args, name)}",
                                  argument=f"--{name}")
    if not PERIOD_RANGE[0] <= args.period <= PERIOD_RANGE[1]:
        raise PhantomPinError(f"{args.period:g} s is outside {PERIOD_RANGE[0]:g}..{PERIOD_RANGE[1]:g} s "
                              "(shorter periods ask more torque than the arm has; longer ones excite nothing)",
                              argument="--period")
    if args.rate < MIN_SAMPLES_PER_HARMONIC * args.harmonics / args.period:
        raise PhantomPinError(f"{args.rate:g} Hz samples the highest harmonic ({args.harmonics} / "
                              f"{args.period:g} s) fewer than {MIN_SAMPLES_PER_HARMONIC} times per cycle; use at least "
                              f"{MIN_SAMPLES_PER_HARMONIC * args.harmonics / args.period:g} Hz", argument="--rate")
    rows = args.rate * args.period * math.ceil(min(args.duration, MAX_ROWS * args.period) / args.period) + 1
    if rows > MAX_ROWS:
        raise PhantomPinError(f"--duration, --rate: {args.duration:g} s at {args.rate:g} Hz is more than "
                              f"{MAX_ROWS} rows "
                              f"(about {MAX_ROWS * 13 * 8 / 1e9:.1f} GB in memory)")


def _plot(args: argparse.Namespace, made: Description, result: Excitation,
          samples: tuple[np.ndarray, ...], effort: np.ndarray) -> str:
    """excite's --plot page: ``samples`` (t s, theta rad, dtheta rad/s, tau N m, in the report's
    terms) with the stops and ``effort``, the joint torque limits (N m) the optimisation kept to."""
    t, theta, dtheta, tau = samples
    limits = made.config.limits.stops
    stops = (np.array(limits.lower), np.array(limits.upper), limits.coupled.theta2_minus_theta3_max,
             limits.coupled.theta3_minus_theta2_max)
    facts = [("model", made.config.name),
             ("excitation", f"{args.harmonics} harmonics per joint, period {args.period:g} s, "
                            f"{len(t)} samples at {args.rate:g} Hz, seed {args.seed}"),
             ("condition number", f"{result.condition:.3g} (general base regressor, columns of unit norm)"),
             ("nearest approach to a stop", f"{result.min_slack:.3f} rad"),
             ("torques", "the model's inverse dynamics plus its friction, in the report's terms (N m)"
                         + ("; the CSV holds OpenHaptics' mN m" if args.convention == "openhaptics" else ""))]
    return plots.run_page(f"phantom-pin excite: {made.config.name}", facts, t, theta, dtheta, tau, stops, effort,
                          "joint torque limit")


def identify_command(args: argparse.Namespace) -> int:
    """phantom-pin identify, for the configuration of --model or --config (and the overrides)."""
    output(args)
    _suffix(args.output, (".yaml", ".yml"), "a YAML overlay")
    report = plot_target(args, "--report")
    recording = _recording(args)
    given = overrides(args)
    made = description(args, given)
    if recording is not None and made.config.gimbal is not None:
        made = held(made, recording.stylus())   # the stylus's load at the bag's gimbal angles
        given = {**given, **stylus_keys(made.config)}   # the overlay carries the posture it was fitted at
    phantom = Phantom(made)
    if args.static:
        return _static_command(args, phantom, recording, given)
    _check_fit(args, phantom, given)
    delay = _delay(args.delay)
    if recording is None:
        check_record(args.log, phantom.config.name, args.convention, "LOG")
    log = read_log(args.log, args.convention) if recording is None else recording.log
    for line in [] if recording is None else recording.lines():
        print(line)
    bar = Progress("identify", 1.0, enabled=False if args.quiet else None)
    try:
        result = identify(log, phantom, cutoff=args.cutoff, structure=args.structure, timing=args.torque_timing,
                          prior_spread=args.prior_spread, delay=delay, gains=not args.fixed_gains,
                          min_speed=args.min_speed, accept=args.accept, given=given, source=args.log.name,
                          progress=bar.update,
                          reference=_reference(args.reference, phantom.config.name, args.convention))
    except RefusedError as error:
        raise PhantomPinError(f"{refusal(error.problems)}; nothing written (--accept writes it anyway)") from None
    finally:
        bar.close()
    for line in result.report():
        print(line)
    for warning in result.warnings():
        warn(warning)              # on stderr, as every command's (and in the overlay's header)
    _write_fit(args, result, phantom, report)
    return 0


def _check_fit(args: argparse.Namespace, phantom: Phantom, given: dict) -> None:
    """identify's --structure and --cutoff checked against the model before any work."""
    if args.structure == "report" and phantom.config.report is None:
        how = " with its --params/--set overrides" if given else ""
        raise PhantomPinError(f"report needs a model in the report's form; {phantom.config.name}{how} "
                              "gives its links in full (use --structure general)", argument="--structure")
    if not (math.isfinite(args.cutoff) and args.cutoff > 0):
        raise PhantomPinError(f"expected a finite positive frequency (Hz), got {args.cutoff!r}", argument="--cutoff")


def _write_fit(args: argparse.Namespace, result: Identification, phantom: Phantom, report: Path | None) -> None:
    """identify's overlay and --report page (both written, or neither), each reported."""
    page = None if report is None else report_page(result, phantom.config.name)
    # --output and --report checked above, before any work; both written, or neither
    write_texts([(args.output, result.text(), "--output")] + ([] if page is None or report is None else
                                                              [(report, page, "--report")]))
    if report is not None:
        print(f"wrote {report}")
    chosen = f"--config {args.config} " if args.config is not None else (
        "" if phantom.config.name == DEFAULT else f"--model {phantom.config.name} ")
    print(f"wrote {args.output} (phantom-pin {chosen}urdf --params {args.output} -o my_phantom.urdf)")
