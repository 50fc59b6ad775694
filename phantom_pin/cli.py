"""The phantom-pin command line: info, check, fk, ik, dynamics, urdf, srdf, mjcf, links, show,
simulate, excite, identify; --model NAME or --config DIR chooses the configuration."""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import re
import sys
import webbrowser
from pathlib import Path

import numpy as np
import pinocchio as pin

from phantom_pin.config import DEFAULT, FILES, MODELS, models, read_overrides
from phantom_pin.config.sampling import random_states
from phantom_pin.description.build import Description, describe, description_of, links_yaml
from phantom_pin.device import cli as device_cli
from phantom_pin.dynamics.loader import load
from phantom_pin.dynamics.model import Phantom
from phantom_pin.exceptions import PhantomPinError
from phantom_pin.identification import commands as identification
from phantom_pin.progress import Progress
from phantom_pin.report import appendix, closed_form
from phantom_pin.validation import output_path, within_box

#: States evaluated at a time by check: memory stays bounded (tens of MB) whatever -n is.
CHECK_CHUNK = 10_000
#: Most states check evaluates: about 4 minutes at the measured 13 microseconds per state.
CHECK_MAX = 20_000_000


class _Parser(argparse.ArgumentParser):
    def __init__(self, *args: object, **kwargs: object) -> None:
        super().__init__(*args, **kwargs)
        # argparse takes "-1e-3" for an option unless it looks like a negative number; its
        # own pattern knows no exponents. No option of ours looks like a number.
        self._negative_number_matcher = re.compile(r"^-(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?$")

    def error(self, message: str) -> None:  # reported by main as one line, exit code 2
        raise PhantomPinError(f"{self.prog.removeprefix('phantom-pin').strip() or 'usage'}: {message}")


def _positive_integer(text: str) -> int:
    """A count such as 1000 or 1e6 (a whole number >= 1)."""
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not (value >= 1 and value.is_integer()):
        raise argparse.ArgumentTypeError(f"expected a positive whole number, got {text!r}")
    return int(value)


def _print(args: argparse.Namespace, data: dict, text: str) -> None:
    print(json.dumps(data, indent=2, allow_nan=False) if args.json else text)


def _warn_limits(theta: object, lower: np.ndarray, upper: np.ndarray, what: str = "theta") -> None:
    """One warning line on stderr if ``theta`` (rad) is outside the box limits."""
    if not within_box(theta, lower, upper):
        print(f"phantom-pin: warning: {what} {_vector(theta, '{:.6g}')} rad is outside the joint "
              f"limits {_vector(lower, '{:.6g}')}..{_vector(upper, '{:.6g}')} rad (computed anyway)",
              file=sys.stderr)


def _vector(values: list[float], spec: str) -> str:
    return "[" + " ".join(spec.format(v) for v in values) + "]"


def _info(args: argparse.Namespace, phantom: Phantom) -> int:
    model, actuation = phantom.model, phantom.config.actuation
    joints = [{"name": model.names[i], "lower": float(model.lowerPositionLimit[i - 1]),
               "upper": float(model.upperPositionLimit[i - 1]),
               "velocity": float(model.velocityLimit[i - 1]), "effort": float(model.effortLimit[i - 1]),
               "armature": float(model.armature[i - 1]),
               "ratio": None if actuation.ratios is None else actuation.ratios[i - 1]} for i in (1, 2, 3)]
    tree = phantom.coupling.tree
    body: dict[int, str] = {}
    for frame in tree.frames:  # the first body frame of a joint is its link
        if frame.type == pin.FrameType.BODY:
            body.setdefault(frame.parentJoint, frame.name)
    links = [{"name": body[i], "mass": tree.inertias[i].mass,
              "com": tree.inertias[i].lever.tolist(),
              "inertia": [tree.inertias[i].inertia[j, k] for j, k in ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2))]}
             for i in range(1, tree.njoints) if tree.inertias[i].mass > 0]
    data = {"model": phantom.config.name, "joints": joints, "links": links,
            "rotor_inertia": None if actuation.motor is None else actuation.motor.rotor_inertia}
    lines = ["joint    lower[rad] upper[rad] vel[rad/s] effort[Nm] armature[kg m2] ratio"]
    lines += [f"{j['name']:8} {j['lower']:10.3f} {j['upper']:10.3f} {j['velocity']:10.2f} "
              f"{j['effort']:10.3f} {j['armature']:15.4e} "
              f"{'-' if j['ratio'] is None else format(j['ratio'], '5.1f'):>5}" for j in joints]
    width = max(len("link"), *(len(lk["name"]) for lk in links))
    lines += ["", f"{'link':{width}} mass[kg]  com[m] (link frame)       inertia xx xy xz yy yz zz at the COM [kg m2]"]
    lines += [f"{lk['name']:{width}} {lk['mass']:8.4f}  {_vector(lk['com'], '{:7.4f}'):26}"
              f"{_vector(lk['inertia'], '{:.3e}')}" for lk in links]
    lines += ["", "rotor inertia: not public (no armature; the links carry the rotors)" if actuation.motor is None
              else f"rotor inertia {actuation.motor.rotor_inertia:.3e} kg m2 (each motor)"]
    given = getattr(args, "overrides", None) or {}
    data["overrides"] = len(given)
    lines.insert(0, f"model {phantom.config.name}" + (f", with {len(given)} overridden number(s) (--params/--set)"
                                                       if given else ""))
    data["device"], device_lines = device_cli.info(phantom)  # stops, friction, motor, encoder
    lines += ["", *device_lines]
    _print(args, data, "\n".join(lines))
    return 0


def _check(args: argparse.Namespace, phantom: Phantom) -> int:
    """Phantom vs closed_form with Phantom's own parameters, in chunks of CHECK_CHUNK
    states; the appendix's printed torques only when the parameters are the report's."""
    if args.n > CHECK_MAX:
        raise PhantomPinError(f"-n: {args.n} states is more than {CHECK_MAX:.0e} (about 4 minutes); check fewer")
    p = phantom.config.report
    if p is None:
        given = (" with the --params/--set overrides (links in full, as identify's general overlay writes them)"
                 if phantom.config.overridden else "")
        raise PhantomPinError(f"check: the model {phantom.config.name}{given} is not written in the report's terms, "
                              f"so the closed form does not apply (tests/test_cad_model.py checks a model in full "
                              f"against an independent derivation)")
    methods = {"forward_kinematics": 1, "spatial_jacobian": 1, "body_jacobian": 1, "mass_matrix": 1,
               "coriolis_matrix": 2, "gravity": 1, "inverse_dynamics": 3}  # name: number of arguments
    worst = {name: [0.0, 0.0] for name in methods}  # max |ours - reference|, max |reference|
    applies = appendix.applies(p)
    as_appendix = dataclasses.replace(p, Iayy=appendix.APPENDIX_IAYY)
    excess = 0.0
    generator = np.random.default_rng(args.seed)
    bar = Progress("check", args.n, enabled=False if args.quiet else None)
    for start in range(0, args.n, CHECK_CHUNK):
        bar.update(start)
        states = random_states(phantom.config.limits, min(CHECK_CHUNK, args.n - start), generator)
        for name, count in methods.items():
            ours = getattr(phantom, name)(*states[:count])
            reference = getattr(closed_form, name)(*states[:count], p)
            worst[name][0] = max(worst[name][0], float(np.abs(ours - reference).max()))
            worst[name][1] = max(worst[name][1], float(np.abs(reference).max()))
        if applies:
            printed, bound = appendix.torques(*states)
            excess = max(excess, float((np.abs(closed_form.inverse_dynamics(*states, as_appendix)
                                                - printed) / bound).max()))
    bar.close()
    rows = [{"check": f"Phantom.{name} vs closed form (relative)", "max_error": error / (scale or 1.0),
             "tolerance": 1e-9} for name, (error, scale) in worst.items()]
    rows.append({"check": "closed form vs appendix Tau1-3 (error / printed rounding)",
                 "max_error": excess if applies else None, "tolerance": 1.0})
    failed = [r for r in rows if r["max_error"] is not None and not r["max_error"] <= r["tolerance"]]
    text = [f"{args.n} random states (seed {args.seed}) inside the joint limits",
            f"{'check':60} {'max error':>10} {'tolerance':>10}"]
    text += [f"{r['check']:60} {r['max_error']:10.2e} {r['tolerance']:10.0e}" if r["max_error"] is not None
             else f"{r['check']:60} {'n/a':>10}  (parameters are not the report's)" for r in rows]
    text.append("FAIL" if failed else "all checks pass")
    _print(args, {"states": args.n, "seed": args.seed, "checks": rows, "passed": not failed}, "\n".join(text))
    return 1 if failed else 0


def _fk(args: argparse.Namespace, phantom: Phantom) -> int:
    g = phantom.forward_kinematics(args.theta)
    _warn_limits(args.theta, phantom.model.lowerPositionLimit, phantom.model.upperPositionLimit)
    _print(args, {"g_st": g.tolist()},
           f"tip position in s [m]: {np.array2string(g[:3, 3], precision=6)}\n"
           f"g_st =\n{np.array2string(g, precision=6, suppress_small=True)}")
    return 0


def _ik(args: argparse.Namespace, phantom: Phantom) -> int:
    theta = phantom.inverse_kinematics(args.position, branch=args.branch)
    _warn_limits(theta, phantom.model.lowerPositionLimit, phantom.model.upperPositionLimit,
                 "the solution theta")
    _print(args, {"theta": theta.tolist()}, f"theta [rad]: {np.array2string(theta, precision=9)}")
    return 0


def _dynamics(args: argparse.Namespace, phantom: Phantom) -> int:
    results = {"M": phantom.mass_matrix(args.theta),
               "C": phantom.coriolis_matrix(args.theta, args.dtheta),
               "N": phantom.gravity(args.theta),
               "tau": phantom.inverse_dynamics(args.theta, args.dtheta, args.ddtheta)}
    _warn_limits(args.theta, phantom.model.lowerPositionLimit, phantom.model.upperPositionLimit)
    text = "\n".join(f"{k} =\n{np.array2string(v, precision=6)}" for k, v in results.items())
    _print(args, {k: v.tolist() for k, v in results.items()}, text)
    return 0


def _source(args: argparse.Namespace) -> str | Path:
    """The model name or the configuration folder the command works on."""
    if args.config is not None and args.model != DEFAULT:
        raise PhantomPinError("--config: give --model or --config, not both")
    if args.config is None and args.model not in models():
        raise PhantomPinError(f"--model: {args.model!r} is not a model ({', '.join(models())}); "
                              "use --config for a folder")
    return args.config if args.config is not None else args.model


def _overrides(args: argparse.Namespace) -> dict[str, float]:
    """The overrides of --params (a YAML file) and then --set KEY=VALUE."""
    try:
        overrides = read_overrides(args.params) if args.params else {}
    except PhantomPinError as error:
        raise PhantomPinError(f"--params: {error}") from None
    overrides.update(_parse_set(args.set))
    return overrides


def _parse_set(items: list[str]) -> dict[str, float]:
    out = {}
    for item in items:
        key, _, value = item.partition("=")
        try:
            out[key] = float(value)
        except ValueError:
            raise PhantomPinError(f"--set: expected KEY=NUMBER, got {item!r}") from None
    return out


def _write(args: argparse.Namespace) -> int:
    """urdf, srdf, mjcf, links: the files of describe(--model or --config, --prefix, --params and --set)."""
    output = output_path(args.output, args.force, "--output", "--force")
    scene = output_path(args.scene, args.force, "--scene", "--force") if getattr(args, "scene", None) else None
    if scene is not None and scene.resolve() == output.resolve():
        raise PhantomPinError(f"--scene: {scene} is the --output file; the scene includes the model, "
                              "give it its own file")
    # the scene includes the model by a path relative to the scene's own folder (MuJoCo resolves it there)
    robot_file = output.name if scene is None else os.path.relpath(output.resolve(), scene.resolve().parent)
    description = describe(_source(args), prefix=args.prefix, overrides=_overrides(args), robot_file=robot_file)
    robot = (description.model or MODELS[DEFAULT]).robot_name
    texts = {"urdf": description.urdf, "srdf": description.srdf, "mjcf": description.mjcf,
             "links": links_yaml(description.config, robot)}
    output.write_text(texts[args.kind])
    print(f"wrote {output}")
    if scene is not None:
        scene.write_text(description.scene)
        print(f"wrote {scene}")
    return 0


def _show(args: argparse.Namespace, description: Description) -> int:
    from phantom_pin.viewer import Viewer  # meshcat is only needed here

    if args.html:
        output_path(args.html, args.force, "--html", "--force")
    robot = load(description)
    if args.theta is not None:
        _warn_limits(args.theta, robot.model.lowerPositionLimit, robot.model.upperPositionLimit)
    with Viewer(robot) as viewer:
        if args.tip_force is not None:
            viewer.set_force(args.tip_force)
        viewer.show(robot.q0 if args.theta is None else args.theta)
        if args.html:
            print(f"wrote {viewer.export_html(args.html, force=args.force)}")
            return 0
        print(f"meshcat viewer at {viewer.url} (Ctrl-C to stop)", flush=True)
        if args.open:
            webbrowser.open(viewer.url)
        viewer.wait()
    return 0


def _parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="phantom-pin", description=__doc__)
    parser.add_argument("--model", default=DEFAULT,
                        help=f"a named configuration: {', '.join(models())} (default {DEFAULT})")
    parser.add_argument("--config", type=Path,
                        help=f"instead of --model, a folder with the parameter files {sorted(FILES.values())}")
    parser.add_argument("--quiet", "-q", action="store_true",
                        help="no progress bar on stderr (shown on a terminal when work takes over 2 s)")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    three = {"nargs": 3, "type": float}
    info = sub.add_parser("info", help="joints, limits, links with mass, COM and inertia, rotor data, "
                                       "the device's stops, friction, motor and encoder with sources")
    check = sub.add_parser("check", help="Phantom vs closed form vs the appendix at N random states")
    check.add_argument("-n", type=_positive_integer, default=1000,
                       help=f"number of random states, e.g. 1000 or 1e6 (default 1000; evaluated "
                            f"{CHECK_CHUNK} at a time)")
    check.add_argument("--seed", type=int, default=0)
    fk = sub.add_parser("fk", help="g_st (eq. 10) at theta (rad)")
    fk.add_argument("theta", metavar="T", **three)
    ik = sub.add_parser("ik", help="theta (rad) that puts the tip at X Y Z (m, frame s)")
    ik.add_argument("position", metavar="P", **three)
    ik.add_argument("--branch", choices=["report", "other"], default="report")
    dyn = sub.add_parser("dynamics", help="M, C, N and tau at a state")
    dyn.add_argument("--theta", required=True, **three)
    dyn.add_argument("--dtheta", default=[0.0, 0.0, 0.0], **three)
    dyn.add_argument("--ddtheta", default=[0.0, 0.0, 0.0], **three)
    for kind in ("urdf", "srdf", "mjcf", "links"):
        gen = sub.add_parser(kind, help=f"write the {kind.upper()} generated from --model or --config"
                             if kind != "links" else "write the links in full (mass, COM, inertia; the "
                             "xacro's links_file) of --model or --config")
        gen.add_argument("--output", "-o", required=True)
        gen.add_argument("--prefix", default="")
        gen.add_argument("--force", "-f", action="store_true", help="overwrite an existing file")
        gen.set_defaults(kind=kind)
        if kind == "mjcf":
            gen.add_argument("--scene", help="also write a scene (floor, light, table) that "
                                             "includes the MJCF of --output (same folder)")
    show = sub.add_parser("show", help="the arm in meshcat: a live viewer on 127.0.0.1, or --html FILE")
    show.add_argument("--theta", metavar="T", help="posture (rad; default: the SRDF's resting)", **three)
    show.add_argument("--tip-force", metavar="F", help="force on the tip (N, frame s), drawn as an arrow",
                      **three)
    show.add_argument("--html", help="write a self-contained HTML file instead of serving")
    show.add_argument("--force", "-f", action="store_true", help="overwrite an existing --html file")
    show.add_argument("--open", action="store_true", help="open the live viewer in a browser")
    device_cli.add_parser(sub)
    identification.add_parsers(sub)
    for command in sub.choices.values():  # every command works on the model with overrides
        command.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                             help="override one number of the parameter files, e.g. l1=0.2096 or "
                                  "segment_a.mass=0.03 (SI units, rad); repeatable")
        command.add_argument("--params", type=Path,
                             help="a YAML file of such overrides, e.g. identify's (applied before --set)")
    for command in (info, check, fk, ik, dyn):
        command.add_argument("--json", action="store_true", help="print JSON")
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run the command line; return the exit code: 0 ok, 1 check failed, 2 bad input or
    an unwritable file (one line on stderr), 130 interrupted by Ctrl-C (128 + SIGINT, one
    line), 141 output pipe closed by its reader (128 + SIGPIPE, silent, as ``yes | head``)."""
    handlers = {"info": _info, "check": _check, "fk": _fk, "ik": _ik, "dynamics": _dynamics,
                "simulate": device_cli.simulate_command, "excite": identification.excite,
                "identify": identification.identify}
    try:
        args = _parser().parse_args(argv)
        if args.command in ("urdf", "srdf", "mjcf", "links"):
            code = _write(args)
        else:  # one Description of --model or --config (and the overrides) for every other command
            overrides = args.overrides = _overrides(args)
            description = (describe(_source(args), overrides=overrides) if overrides
                           else description_of(_source(args), "--config" if args.config else "--model"))
            code = (_show(args, description) if args.command == "show"
                    else handlers[args.command](args, Phantom(description)))
        sys.stdout.flush()  # a closed pipe raises here, not at exit
        return code
    except BrokenPipeError:
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())  # no error at exit either
        return 141
    except KeyboardInterrupt:
        print("phantom-pin: interrupted", file=sys.stderr)
        return 130
    except (PhantomPinError, ValueError, OSError) as error:
        message = f"{error.filename}: {error.strerror}" if isinstance(error, OSError) and error.filename \
            else str(error)
        print(f"phantom-pin: error: {' '.join(message.split())}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
