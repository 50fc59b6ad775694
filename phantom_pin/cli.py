"""The phantom-pin command line: info, check, fk, ik, dynamics, urdf, srdf, mjcf, show, excite, identify."""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys
import tempfile
import webbrowser
from pathlib import Path

import numpy as np
import pinocchio as pin

from phantom_pin import appendix, closed_form
from phantom_pin.description import generate_srdf, generate_urdf
from phantom_pin.exceptions import PhantomPinError
from phantom_pin.identification import commands as identification
from phantom_pin.loader import PhantomLoader, load
from phantom_pin.mjcf import generate_mjcf
from phantom_pin.model import Phantom
from phantom_pin.parameters import (CONFIG_DIR, PARAMETER_FILES, random_states, read_overrides,
                                    write_overridden)


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> None:  # reported by main as one line, exit code 2
        raise PhantomPinError(f"{self.prog.removeprefix('phantom-pin').strip() or 'usage'}: {message}")


def _print(args: argparse.Namespace, data: dict, text: str) -> None:
    print(json.dumps(data, indent=2) if args.json else text)


def _vector(values: list[float], spec: str) -> str:
    return "[" + " ".join(spec.format(v) for v in values) + "]"


def _info(args: argparse.Namespace, phantom: Phantom) -> int:
    model, p = phantom.model, phantom.parameters
    joints = [{"name": model.names[i], "lower": float(model.lowerPositionLimit[i - 1]),
               "upper": float(model.upperPositionLimit[i - 1]),
               "velocity": float(model.velocityLimit[i - 1]), "effort": float(model.effortLimit[i - 1]),
               "armature": float(model.armature[i - 1]), "ratio": p.ratios[i - 1]} for i in (1, 2, 3)]
    tree = phantom.coupling.tree
    body: dict[int, str] = {}
    for frame in tree.frames:  # the first body frame of a joint is its link
        if frame.type == pin.FrameType.BODY:
            body.setdefault(frame.parentJoint, frame.name)
    links = [{"name": body[i], "mass": tree.inertias[i].mass,
              "com": tree.inertias[i].lever.tolist(),
              "inertia": np.diag(tree.inertias[i].inertia).tolist()}
             for i in range(1, tree.njoints) if tree.inertias[i].mass > 0]
    data = {"joints": joints, "links": links, "rotor_inertia": p.rotor_inertia}
    lines = ["joint    lower[rad] upper[rad] vel[rad/s] effort[Nm] armature[kg m2] ratio"]
    lines += [f"{j['name']:8} {j['lower']:10.3f} {j['upper']:10.3f} {j['velocity']:10.2f} "
              f"{j['effort']:10.3f} {j['armature']:15.4e} {j['ratio']:5.1f}" for j in joints]
    lines += ["", "link            mass[kg]  com[m] (link frame)       inertia diagonal at the COM [kg m2]"]
    lines += [f"{lk['name']:15} {lk['mass']:8.4f}  {_vector(lk['com'], '{:7.4f}'):26}"
              f"{_vector(lk['inertia'], '{:.3e}')}" for lk in links]
    lines += ["", f"rotor inertia {p.rotor_inertia:.3e} kg m2 (each motor)"]
    _print(args, data, "\n".join(lines))
    return 0


def _check(args: argparse.Namespace, phantom: Phantom) -> int:
    p = phantom.parameters
    theta, dtheta, ddtheta = random_states(p, args.n, args.seed)
    rows = []
    for name, arguments in (("forward_kinematics", (theta,)), ("spatial_jacobian", (theta,)),
                            ("body_jacobian", (theta,)), ("mass_matrix", (theta,)),
                            ("coriolis_matrix", (theta, dtheta)), ("gravity", (theta,)),
                            ("inverse_dynamics", (theta, dtheta, ddtheta))):
        ours, reference = getattr(phantom, name)(*arguments), getattr(closed_form, name)(*arguments)
        error = float(np.abs(ours - reference).max() / np.abs(reference).max())
        rows.append({"check": f"Phantom.{name} vs closed form (relative)", "max_error": error,
                     "tolerance": 1e-9})
    printed, bound = appendix.torques(theta, dtheta, ddtheta)
    as_appendix = dataclasses.replace(p, Iayy=appendix.APPENDIX_IAYY)
    excess = np.abs(closed_form.inverse_dynamics(theta, dtheta, ddtheta, as_appendix) - printed) / bound
    rows.append({"check": "closed form vs appendix Tau1-3 (error / printed rounding)",
                 "max_error": float(excess.max()), "tolerance": 1.0})
    failed = [r for r in rows if not r["max_error"] <= r["tolerance"]]
    text = [f"{args.n} random states (seed {args.seed}) inside the joint limits",
            f"{'check':60} {'max error':>10} {'tolerance':>10}"]
    text += [f"{r['check']:60} {r['max_error']:10.2e} {r['tolerance']:10.0e}" for r in rows]
    text.append("FAIL" if failed else "all checks pass")
    _print(args, {"states": args.n, "seed": args.seed, "checks": rows, "passed": not failed}, "\n".join(text))
    return 1 if failed else 0


def _fk(args: argparse.Namespace, phantom: Phantom) -> int:
    g = phantom.forward_kinematics(args.theta)
    _print(args, {"g_st": g.tolist()},
           f"tip position in s [m]: {np.array2string(g[:3, 3], precision=6)}\n"
           f"g_st =\n{np.array2string(g, precision=6, suppress_small=True)}")
    return 0


def _ik(args: argparse.Namespace, phantom: Phantom) -> int:
    theta = phantom.inverse_kinematics(args.position, branch=args.branch)
    _print(args, {"theta": theta.tolist()}, f"theta [rad]: {np.array2string(theta, precision=9)}")
    return 0


def _dynamics(args: argparse.Namespace, phantom: Phantom) -> int:
    results = {"M": phantom.mass_matrix(args.theta),
               "C": phantom.coriolis_matrix(args.theta, args.dtheta),
               "N": phantom.gravity(args.theta),
               "tau": phantom.inverse_dynamics(args.theta, args.dtheta, args.ddtheta)}
    text = "\n".join(f"{k} =\n{np.array2string(v, precision=6)}" for k, v in results.items())
    _print(args, {k: v.tolist() for k, v in results.items()}, text)
    return 0


def _parse_set(items: list[str]) -> dict[str, float]:
    out = {}
    for item in items:
        key, _, value = item.partition("=")
        try:
            out[key] = float(value)
        except ValueError:
            raise PhantomPinError(f"--set: expected KEY=NUMBER, got {item!r}") from None
    return out


def _refuse_overwrite(path: Path, force: bool, option: str) -> None:
    if path.exists() and not force:
        raise PhantomPinError(f"{option}: {path} exists; add --force to overwrite it")


def _urdf(args: argparse.Namespace, phantom: Phantom | None) -> int:
    output = Path(args.output)
    _refuse_overwrite(output, args.force, "--output")
    try:
        overrides = read_overrides(args.params) if args.params else {}
    except PhantomPinError as error:
        raise PhantomPinError(f"--params: {error}") from None
    overrides.update(_parse_set(args.set))
    scene = Path(args.scene) if getattr(args, "scene", None) else None
    if scene is not None:
        _refuse_overwrite(scene, args.force, "--scene")
    with tempfile.TemporaryDirectory() as folder:
        config = write_overridden(overrides, folder, args.config) if overrides else args.config
        if args.kind == "mjcf":
            text, scene_text = generate_mjcf(args.prefix, config, robot_file=output.name)
        else:
            text = (generate_urdf if args.kind == "urdf" else generate_srdf)(args.prefix, config)
    output.write_text(text)
    print(f"wrote {output}")
    if scene is not None:
        scene.write_text(scene_text)
        print(f"wrote {scene}")
    return 0


def _show(args: argparse.Namespace, phantom: Phantom | None) -> int:
    from phantom_pin.viewer import Viewer  # meshcat is only needed here

    if args.html:
        _refuse_overwrite(Path(args.html), args.force, "--html")
    with tempfile.TemporaryDirectory() as folder:
        loader = PhantomLoader
        if Path(args.config).resolve() != CONFIG_DIR.resolve():
            urdf, srdf = Path(folder) / "phantom_1_5.urdf", Path(folder) / "phantom_1_5.srdf"
            urdf.write_text(generate_urdf("", args.config))
            srdf.write_text(generate_srdf("", args.config))
            loader = type("ConfigLoader", (PhantomLoader,), {"urdf_path": urdf, "srdf_path": srdf})
        robot = load(loader)
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
    parser.add_argument("--config", type=Path, default=CONFIG_DIR,
                        help=f"folder with the parameter files {sorted(PARAMETER_FILES.values())}")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    three = {"nargs": 3, "type": float}
    info = sub.add_parser("info", help="joints, limits, links with mass, COM and inertia, rotor data")
    check = sub.add_parser("check", help="Phantom vs closed form vs the appendix at N random states")
    check.add_argument("-n", type=int, default=1000, help="number of random states (default 1000)")
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
    for kind in ("urdf", "srdf", "mjcf"):
        gen = sub.add_parser(kind, help=f"write the {kind.upper()} generated from --config")
        gen.add_argument("--output", "-o", required=True)
        gen.add_argument("--prefix", default="")
        gen.add_argument("--force", "-f", action="store_true", help="overwrite an existing file")
        gen.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                         help="override one number of the parameter files, e.g. l1=0.2096 or "
                              "segment_a.mass=0.03 (SI units, rad); repeatable")
        gen.add_argument("--params", type=Path, help="a YAML file of such overrides (applied before --set)")
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
    identification.add_parsers(sub)
    for command in (info, check, fk, ik, dyn):
        command.add_argument("--json", action="store_true", help="print JSON")
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run the command line; return the exit code (0 ok, 1 check failed, 2 bad input)."""
    handlers = {"info": _info, "check": _check, "fk": _fk, "ik": _ik, "dynamics": _dynamics,
                "urdf": _urdf, "srdf": _urdf, "mjcf": _urdf, "show": _show,
                "excite": identification.excite, "identify": identification.identify}
    try:
        args = _parser().parse_args(argv)
        if args.command == "check" and args.n < 1:
            raise PhantomPinError("-n: expected a positive number of states")
        phantom = (None if args.command in ("urdf", "srdf", "mjcf", "show", "excite", "identify")
                   else Phantom(args.config))
        return handlers[args.command](args, phantom)
    except (PhantomPinError, ValueError) as error:
        print(f"phantom-pin: error: {error}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
