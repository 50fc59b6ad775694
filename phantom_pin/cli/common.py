"""What every command of ``phantom-pin`` shares: the parser class, the model options
(--model, --config, --params, --set) turned into a Description or a Phantom, output files,
printing and warnings."""

from __future__ import annotations

import argparse
import itertools
import json
import os
import re
import stat
import sys
import tempfile
from pathlib import Path
from typing import Any

from phantom_pin._validation import output_path, within_box
from phantom_pin.config import DEFAULT, models, read_overrides, renamed
from phantom_pin.description.build import Description, describe, description_of
from phantom_pin.dynamics.phantom import Phantom
from phantom_pin.exceptions import PhantomPinError
from phantom_pin.viewer import plots

#: The options that choose the model, accepted before or after the command (dest: option).
MODEL_OPTIONS = {"model": "--model", "config": "--config", "params": "--params", "set": "--set"}


class Parser(argparse.ArgumentParser):
    """argparse with one-line errors (PhantomPinError, printed by main) and numbers with
    exponents, such as -1e-3, taken as values rather than options."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        # argparse takes "-1e-3" for an option unless it looks like a negative number; its
        # own pattern knows no exponents. No option of ours looks like a number.
        self._negative_number_matcher = re.compile(r"^-(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?$")

    def error(self, message: str) -> Any:  # reported by main as one line, exit code 2
        raise PhantomPinError(f"{self.prog.removeprefix('phantom-pin').strip() or 'usage'}: {message}")


class Once(argparse.Action):
    """An option that may be given once: a second --model is refused, not silently taken."""

    def __call__(self, parser: argparse.ArgumentParser, namespace: argparse.Namespace, values: Any,
                 option_string: str | None = None) -> None:
        if given(namespace, self.dest):
            raise PhantomPinError("given twice; give it once", argument=option_string)
        setattr(namespace, "_given_" + self.dest, True)
        setattr(namespace, self.dest, values)


def given(args: argparse.Namespace, dest: str) -> bool:
    """Whether the option of ``dest`` was given on the command line (not its default)."""
    return bool(getattr(args, "_given_" + dest, False))


def add_model_options(parser: argparse.ArgumentParser, suffix: str = "") -> None:
    """--model, --config, --params and --set on ``parser``; ``suffix`` distinguishes the
    copies after the command (their dests end with it and default to absent)."""
    absent: dict[str, Any] = {"default": argparse.SUPPRESS} if suffix else {}
    parser.add_argument("--model", dest="model" + suffix, action=Once, **(absent or {"default": DEFAULT}),
                        help=f"a named configuration: {', '.join(models())} (default {DEFAULT})")
    parser.add_argument("--config", dest="config" + suffix, type=Path, action=Once, **absent,
                        help="instead of --model, a folder of parameter files (see robots/phantom_description/config)")
    parser.add_argument("--params", dest="params" + suffix, type=Path, action=Once, **absent,
                        help="a YAML file of overrides, e.g. identify's (applied before --set)")
    parser.add_argument("--set", dest="set" + suffix, action="append", metavar="KEY=VALUE",
                        **(absent or {"default": []}),
                        help="override one number of the parameter files, e.g. l1=0.2096 or "
                             "segment_a.mass=0.03 (SI units, rad); repeatable")


def merge_model_options(args: argparse.Namespace, suffix: str) -> None:
    """Fold the model options given after the command into those given before it; an option
    given on both sides is refused, except --set, whose items add up."""
    for dest, option in MODEL_OPTIONS.items():
        after = args.__dict__.pop(dest + suffix, None)
        if after is None:
            continue
        if dest == "set":
            args.set = [*args.set, *after]
        elif given(args, dest):
            raise PhantomPinError("given before and after the command; give it once", argument=option)
        else:
            setattr(args, dest, after)


def source(args: argparse.Namespace) -> str | Path:
    """The model name or the configuration folder the command works on."""
    if args.config is not None and args.model != DEFAULT:
        raise PhantomPinError("give --model or --config, not both", argument="--config")
    if args.config is None and args.model not in models():
        renamed(args.model, "--model")
        raise PhantomPinError(f"{args.model!r} is not a model ({', '.join(models())}); "
                              "use --config for a folder", argument="--model")
    return args.config if args.config is not None else args.model


def overrides(args: argparse.Namespace) -> dict[str, object]:
    """The overrides of --params (a YAML file) and then --set KEY=VALUE."""
    try:
        given: dict[str, object] = dict(read_overrides(args.params)) if args.params else {}
    except PhantomPinError as error:
        raise PhantomPinError(str(error), argument="--params") from None
    set_here: set[str] = set()
    for item in args.set:
        key, _, value = item.partition("=")
        if not key.strip():
            raise PhantomPinError(f"expected KEY=NUMBER, got {item!r} (no key)", argument="--set")
        if key in set_here:
            raise PhantomPinError(f"{key} given twice; give it once", argument="--set")
        set_here.add(key)
        try:
            given[key] = float(value)
        except ValueError:
            raise PhantomPinError(f"expected KEY=NUMBER, got {item!r}", argument="--set") from None
    return given


def description(args: argparse.Namespace, given: dict[str, object] | None = None, **kwargs: Any) -> Description:
    """The Description of --model or --config with ``given`` overrides (default: those of
    --params and --set); ``kwargs`` go to describe() (prefix, robot_file)."""
    given = overrides(args) if given is None else given
    if given or kwargs:
        return describe(source(args), overrides=given, **kwargs)
    return description_of(source(args), "--config" if args.config else "--model")


def phantom(args: argparse.Namespace) -> Phantom:
    """The Phantom of --model or --config with the overrides."""
    return Phantom(description(args))


def output(args: argparse.Namespace, option: str = "--output") -> Path:
    """The file named by ``option`` (its dest in ``args``), checked before any work: not a
    folder, its folder exists, not overwritten without --force."""
    value = getattr(args, option.lstrip("-").replace("-", "_"))
    if value is None or str(value) == "":
        raise PhantomPinError("empty; give a file name", argument=option)
    return output_path(value, args.force, option, "--force")


def write_text(path: Path, text: str, option: str = "--output") -> None:
    """``text`` into the file ``path``; PhantomPinError naming ``option`` if it cannot be written."""
    write_texts([(path, text, option)])


def _unwritable(path: Path, error: OSError, option: str) -> PhantomPinError:
    return PhantomPinError(f"cannot write {path} ({error.strerror})", argument=option)


def write_texts(files: list[tuple[Path, str, str]]) -> None:
    """Each (path, text, option) written, or none (PhantomPinError naming the option of the
    first that cannot be): each text goes first into a temporary file beside its path (which
    tries the folder's permissions and space), then every one is renamed into place. A path
    that exists and is no regular file (a device such as /dev/null or /dev/full, a pipe) is
    not renamed over: it is written in place once the others are staged (a second such path
    after a first written is the one case where something stays written). A symbolic link is
    followed: its target is replaced, the link kept."""
    staged: list[tuple[str, Path]] = []
    mask = os.umask(0)
    os.umask(mask)
    try:
        for path, text, option in files:
            if path.exists() and not path.is_file():
                continue
            real = path.resolve()
            handle, temporary = tempfile.mkstemp(dir=real.parent, prefix=f".{real.name}.", suffix=".tmp")
            staged.append((temporary, real))
            mode = stat.S_IMODE(path.stat().st_mode) if path.exists() else 0o666 & ~mask
            try:
                with os.fdopen(handle, "w", encoding="utf-8") as stream:
                    stream.write(text)
                os.chmod(temporary, mode)
            except OSError as error:
                raise _unwritable(path, error, option) from None
        for path, text, option in files:
            if path.exists() and not path.is_file():
                try:
                    path.write_text(text, encoding="utf-8")
                except OSError as error:
                    raise _unwritable(path, error, option) from None
    except BaseException:
        for temporary, _ in staged:
            Path(temporary).unlink(missing_ok=True)
        raise
    for temporary, path in staged:
        os.replace(temporary, path)


#: The comment line, second in a trajectory or log the command line writes, that records the model
#: (config.name: a model's name or a folder's path) and the convention of its columns.
RECORD = re.compile(r"#\s*phantom-pin:\s*model (?P<model>.+), convention (?P<convention>\w+)\s*")


def csv_text(header: list[str], table: Any, model: str, convention: str) -> str:
    """A trajectory's or log's CSV: the ``header`` line, the record of ``model`` and ``convention``
    (RECORD; phantom_pin.identification.data.io skips # lines, as numpy.loadtxt does; pandas with
    comment="#"), then the rows of ``table`` (N, len(header)) in their shortest exact decimals."""
    rows = (",".join(map(repr, row)) for row in table.tolist())
    return "\n".join([",".join(header), f"# phantom-pin: model {model}, convention {convention}", *rows]) + "\n"


def check_record(path: Path, model: str, convention: str, option: str) -> None:
    """PhantomPinError naming ``option`` if the file at ``path`` records (RECORD, before its first
    row of data) another model or convention than ``model`` and ``convention``, the ones given;
    a file without the record (written before 0.5.0, or by other tools) is read as it is. A file
    that cannot be read is left to its reader's error."""
    try:
        with open(path, encoding="utf-8-sig") as stream:
            lines = [line.strip() for line in itertools.islice(stream, 64)]
    except (OSError, UnicodeDecodeError):
        return
    data = [i for i, line in enumerate(lines) if line and not line.startswith("#")]
    for line in lines[:data[1] if len(data) > 1 else len(lines)]:
        if not line.startswith("#") or "phantom-pin" not in line:
            continue
        found = RECORD.fullmatch(line)
        if found is None:
            raise PhantomPinError(f"{path}: its line {line[:60]!r} is not '# phantom-pin: model NAME, convention "
                                  "NAME'", argument=option)
        if (found["model"], found["convention"]) != (model, convention):
            raise PhantomPinError(f"{path} was written for the model {found['model']} in the {found['convention']} "
                                  f"convention, read here for the model {model} in the {convention} convention (give "
                                  "--model and --convention as written, or delete its '# phantom-pin' line)",
                                  argument=option)
        return


def show(args: argparse.Namespace, data: dict, text: str) -> None:
    """Print ``data`` as JSON with --json, else ``text``."""
    emit((json.dumps(data, indent=2, allow_nan=False) if getattr(args, "json", False) else text) + "\n")


def emit(text: str) -> None:
    """Write ``text`` to standard output in full, or raise BrokenPipeError (main: exit 141).
    Unbuffered (PYTHONUNBUFFERED, python -u), sys.stdout writes once to the file descriptor, and
    a reader that closes the pipe part way leaves a short write and no error: the rest is lost
    silently, and the command exits 0."""
    buffer = getattr(sys.stdout, "buffer", None)
    if buffer is None:  # a replaced stdout (a test's capture)
        sys.stdout.write(text)
        return
    sys.stdout.flush()
    data = memoryview(text.encode(sys.stdout.encoding or "utf-8"))
    while data:
        data = data[buffer.write(data) or 0:]


def vector(values: Any, spec: str) -> str:
    """``values`` formatted with ``spec`` as "[a b c]"."""
    return "[" + " ".join(spec.format(v) for v in values) + "]"


def warn(message: str) -> None:
    """One warning line on standard error."""
    print(f"phantom-pin: warning: {message}", file=sys.stderr)


def warn_limits(theta: Any, lower: Any, upper: Any, what: str = "theta") -> None:
    """One warning line on stderr if ``theta`` (rad) is outside the box limits."""
    if not within_box(theta, lower, upper):
        warn(f"{what} {vector(theta, '{:.6g}')} rad is outside the joint limits {vector(lower, '{:.6g}')}.."
             f"{vector(upper, '{:.6g}')} rad (computed anyway)")


def add_gimbal(command: argparse.ArgumentParser, what: str) -> None:
    """The option --gimbal G1 G2 G3 (rad) of a command: ``what`` the angles do."""
    command.add_argument("--gimbal", metavar="G", nargs=3, type=float,
                         help=f"the stylus gimbal's angles (rad, OpenHaptics' raw gimbal angles; a model with a "
                              f"gimbal, the Touch): {what}")


def warn_gimbal(gimbal: Any, robot: Phantom) -> None:
    """A warning when --gimbal's angles lie outside the gimbal's range (as warn_limits' for theta)."""
    if gimbal is not None and robot.config.gimbal is not None:
        warn_limits(gimbal, robot.config.gimbal.lower, robot.config.gimbal.upper, "gimbal")


def positive_integer(text: str) -> int:
    """A count such as 1000 or 1e6 (a whole number >= 1)."""
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not (value >= 1 and value.is_integer()):
        raise argparse.ArgumentTypeError(f"expected a positive whole number, got {text!r}")
    return int(value)


def add_plot_option(parser: argparse.ArgumentParser, what: str) -> None:
    """``--plot FILE``: one self-contained HTML page of ``what`` (phantom_pin.viewer.plots)."""
    parser.add_argument("--plot", type=Path, metavar="FILE.html", action=Once,
                        help=f"also write {what} as one self-contained HTML page (matplotlib's SVG, no script; "
                             "needs the plots extra: pip install 'phantom_pin[plots]'); --force overwrites it")


def plot_target(args: argparse.Namespace, option: str = "--plot") -> Path | None:
    """The page named by ``option`` (--plot, identify's --report) checked before any work (an
    .html name, not --output's, writable as output() checks, matplotlib installed), or None
    without it."""
    if getattr(args, option.lstrip("-")) is None:
        return None
    target = output(args, option)
    if target.suffix.lower() not in (".html", ".htm"):
        raise PhantomPinError(f"{target}: the plot is an HTML page; name a .html file", argument=option)
    if args.output is not None and Path(args.output).resolve() == target.resolve():
        raise PhantomPinError(f"{target} is the --output file; give two files", argument=option)
    plots.require_matplotlib()
    return target
