"""CSV files of identification: the excitation trajectory and the device log.

Log: header ``t,theta1,theta2,theta3,tau1,tau2,tau3`` (more columns allowed, any order, any case,
quoted or with units in [] as simulate writes them; separated by commas, semicolons or tabs;
a UTF-8 byte order mark, blank lines and # comment lines are skipped): time
(s) at a fixed rate, joint angles (rad, the report's theta, as measured) and joint torques
(N m, as commanded); or, in OpenHaptics' convention (``read_log(path, "openhaptics")``), its
joint angles (rad) and joint torques (mN m), converted by phantom_pin.interfaces.conventions. ``read_log``
raises LogError with one line on a malformed log.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np

from phantom_pin._validation import as_states, fixed_rate, output_path, uneven
from phantom_pin.exceptions import LogError
from phantom_pin.interfaces import conventions

LOG_COLUMNS = ("t", "theta1", "theta2", "theta3", "tau1", "tau2", "tau3")
TRAJECTORY_COLUMNS = ("t", "theta1", "theta2", "theta3", "dtheta1", "dtheta2", "dtheta3",
                      "ddtheta1", "ddtheta2", "ddtheta3", "tau1", "tau2", "tau3")
#: Shortest accepted log (s) and largest relative spread of the sampling interval.
MIN_DURATION, RATE_TOLERANCE = 2.0, 0.01


@dataclasses.dataclass(frozen=True)
class Log:
    """A device's log: times ``t`` (N,) s, strictly increasing; joint angles ``theta`` (N, 3)
    rad (the report's); joint torques ``tau`` (N, 3) N m; all finite (LogError naming ``log``
    otherwise)."""

    t: np.ndarray       # (N,) s
    theta: np.ndarray   # (N, 3) rad
    tau: np.ndarray     # (N, 3) N m

    def __post_init__(self) -> None:
        try:
            arrays = [np.asarray(x, dtype=float) for x in (self.t, self.theta, self.tau)]
        except (TypeError, ValueError):
            raise LogError("t, theta and tau must be arrays of numbers", argument="log") from None
        t, theta, tau = arrays
        if t.ndim != 1 or len(t) < 2 or theta.shape != (len(t), 3) or tau.shape != (len(t), 3):
            raise LogError(f"expected t (N,), theta (N, 3), tau (N, 3) with N >= 2, got {t.shape}, "
                           f"{theta.shape}, {tau.shape}", argument="log")
        if not all(np.isfinite(x).all() for x in arrays):
            raise LogError("t, theta and tau must be finite (no NaN or inf)", argument="log")
        if not (np.diff(t) > 0).all():
            raise LogError("the times t must increase strictly", argument="log")
        for name, value in zip(("t", "theta", "tau"), arrays):
            object.__setattr__(self, name, value)

    @property
    def rate(self) -> float:
        """The log's rate (Hz), (N - 1) / its duration."""
        return fixed_rate(self.t)


#: Rows formatted at once by write_csv.
_CHUNK = 10_000


def write_csv(path: Path | str, columns: tuple[str, ...], table: np.ndarray) -> None:
    """``columns`` as a header line, then ``table``'s rows, each number with 17 significant digits
    (what np.savetxt(..., fmt="%.17g") writes, byte for byte), formatted 10 000 rows at a time in
    one pass each: half savetxt's time, and memory bounded for any length."""
    rows = np.asarray(table, dtype=float)
    rows = rows[:, None] if rows.ndim == 1 else rows
    line = ",".join(["%.17g"] * rows.shape[1]) + "\n"
    with open(path, "w", encoding="ascii") as file:
        if columns:
            file.write(",".join(columns) + "\n")
        for start in range(0, len(rows), _CHUNK):
            part = rows[start:start + _CHUNK]
            file.write((line * len(part)) % tuple(part.ravel().tolist()))


def write_log(path: Path | str, t: object, theta: object, tau: object, force: bool = False) -> None:
    """Write a log: times ``t`` (N,) s, ``theta`` (N, 3) rad and ``tau`` (N, 3) N m, finite, as
    read_log reads it. An existing file is kept unless ``force``: LogError naming the argument."""
    if not isinstance(path, (str, Path)):
        raise LogError(f"expected a file path, got {path!r}", argument="path")
    if not isinstance(force, bool):
        raise LogError(f"expected True or False, got {force!r}", argument="force")
    path = output_path(path, force, "path", error=LogError)
    try:
        times = np.asarray(t, dtype=float)
    except (TypeError, ValueError):
        raise LogError(f"expected numbers (s), got {t!r:.60}", argument="t") from None
    angles, _ = as_states(theta, "theta")
    torques, _ = as_states(tau, "tau")
    log = Log(times, angles, torques)  # the log's one validation: shapes, finite, increasing (naming log)
    write_csv(path, LOG_COLUMNS, np.column_stack([log.t, log.theta, log.tau]))


def _read_table(path: Path, columns: tuple[str, ...]) -> tuple[list[tuple[int, str]], dict[str, np.ndarray]]:
    """(data lines as (line number, text), {column: values}) of the CSV at ``path``, whose
    header must name ``columns`` (module doc: the dialects it takes); LogError naming the line
    of a bad row. The header is the first data line; its units (in []) by column, _units."""
    lines = _data_lines(path)
    first = lines[0][1]
    separator = max((",", ";", "\t"), key=first.count)        # the dialects spreadsheets write
    header = [_column_name(name) for name in first.split(separator)]
    missing = [c for c in columns if c not in header]
    if missing:
        raise LogError(f"{path}: missing column(s) {', '.join(missing)} (header must name "
                       f"{','.join(columns)}, in any order, case or quotes, with or without units in [])")
    twice = [c for c in columns if header.count(c) > 1]
    if twice:
        raise LogError(f"{path}: the header names {twice[0]} {header.count(twice[0])} times; name each column once")
    table = _numbers(path, lines[1:], separator, len(header))
    if not np.isfinite(table).all():
        row = lines[1 + int(np.where(~np.isfinite(table).all(axis=1))[0][0])][0]
        raise LogError(f"{path}: NaN or inf on line {row}")
    return lines, {name: table[:, header.index(name)] for name in columns}


def _data_lines(path: Path) -> list[tuple[int, str]]:
    """(line number, text) of the lines of the file at ``path`` that hold data (blank lines and
    # comments skipped); LogError where it cannot be read as text or holds none."""
    try:
        text = path.read_text(encoding="utf-8-sig")           # a UTF-8 byte order mark is dropped
    except OSError as error:
        raise LogError(f"{path}: cannot read ({error.strerror})", argument="path") from None
    except UnicodeDecodeError as error:
        raise LogError(f"{path}: not a text file (not UTF-8 at byte {error.start})", argument="path") from None
    # (line number, text) of the lines that hold data: blank lines and # comments are skipped
    lines = [(number, line) for number, line in enumerate(text.splitlines(), start=1)
             if line.strip() and not line.lstrip().startswith("#")]
    if not lines:
        raise LogError(f"{path}: empty file")
    return lines


def _numbers(path: Path, lines: list[tuple[int, str]], separator: str, width: int) -> np.ndarray:
    """The (rows, ``width``) numbers of the data ``lines``: NumPy parses them at once where every
    line has ``width`` values and none is quoted (the values Python's float gives, at a tenth of
    its time: a 20 s log at 1 kHz took 0.15 s); otherwise line by line, and LogError naming the
    first line that has the wrong count of values or a value that is not a number."""
    if all(line.count(separator) == width - 1 for _, line in lines) and not any(
            '"' in line or "'" in line for _, line in lines):
        try:
            return np.array(separator.join(line for _, line in lines).split(separator), dtype=float).reshape(-1, width)
        except ValueError:
            pass                                    # the line by line reading names the line
    rows = []
    for number, line in lines:
        values = line.split(separator)
        if len(values) != width:
            raise LogError(f"{path}: line {number} has {len(values)} values, the header {width}")
        try:
            rows.append([float(v.strip().strip('"').strip("'")) for v in values])
        except ValueError:
            raise LogError(f"{path}: line {number} holds a value that is not a number: {line.strip()[:60]!r}") from None
    return np.array(rows, dtype=float).reshape(-1, width)


def read_postures(path: Path | str) -> tuple[np.ndarray, np.ndarray] | None:
    """(theta (N, 3) rad, tau (N, 3) N m) of a CSV of rest postures and their holding torques
    (header theta1,theta2,theta3,tau1,tau2,tau3 in the report's convention, no t column), or None
    where its header names a time column t (a log: read_log)."""
    lines, column = _read_table(Path(path), ("theta1", "theta2", "theta3", "tau1", "tau2", "tau3"))
    separator = max((",", ";", "\t"), key=lines[0][1].count)
    if "t" in [_column_name(name) for name in lines[0][1].split(separator)]:
        return None
    return (np.column_stack([column[f"theta{j}"] for j in (1, 2, 3)]),
            np.column_stack([column[f"tau{j}"] for j in (1, 2, 3)]))


def read_trajectory(path: Path | str, convention: str = "report") -> tuple[np.ndarray, ...]:
    """(t, theta, dtheta, ddtheta, tau) of an excitation trajectory (excite's CSV: s, rad, rad/s,
    rad/s^2, N m), each (N,) or (N, 3), at a fixed rate, in the report's theta and N m: its columns
    are in the ``convention`` "report" or "openhaptics" (as read_log's; angles, rates and
    accelerations by the same linear map, torques in mN m)."""
    if convention not in ("report", "openhaptics"):
        raise LogError(f"expected 'report' or 'openhaptics', got {convention!r}", argument="convention")
    path = Path(path)
    _, column = _read_table(path, TRAJECTORY_COLUMNS)
    t = column["t"]
    step = np.diff(t)
    if len(t) < 2 or not (step > 0).all() or uneven(step, RATE_TOLERANCE):
        raise LogError(f"{path}: the times must increase at a fixed rate")
    theta, dtheta, ddtheta, tau = (np.column_stack([column[f"{name}{j}"] for j in (1, 2, 3)])
                                   for name in ("theta", "dtheta", "ddtheta", "tau"))
    _consistent(path, "theta", "dtheta", t, theta, dtheta)
    _consistent(path, "dtheta", "ddtheta", t, dtheta, ddtheta)
    if convention == "openhaptics":
        theta, dtheta, ddtheta = (conventions.theta_from_openhaptics(x) for x in (theta, dtheta, ddtheta))
        tau = conventions.tau_from_openhaptics_torque(tau)
    return t, theta, dtheta, ddtheta, tau


#: Largest relative disagreement between a trajectory's column and the rate of change of the
#: one before it (central differences of a smooth trajectory sampled at 100 Hz or faster agree
#: within 1e-3; a unit slip is a factor of 57.3 or 1000).
DERIVATIVE_TOLERANCE = 0.01
#: Unit slips recognised by the factor they leave between a column and its derivative.
UNIT_SLIPS = ((180 / np.pi, "are the angles in degrees?"), (np.pi / 180, "are the rates in degrees?"),
              (1e-3, "is t in ms?"), (1e3, "is t in s and the rest per ms?"))


def _consistent(path: Path, name: str, rate_name: str, t: np.ndarray, values: np.ndarray,
                rates: np.ndarray) -> None:
    """Raise LogError unless ``rates`` is the rate of change of ``values`` (over ``t``, s): the
    least-squares factor between the central differences and ``rates`` must be 1 within
    DERIVATIVE_TOLERANCE; a known unit slip is named."""
    if len(t) < 3 or not np.any(rates):
        return
    differences = np.gradient(values, t, axis=0)
    with np.errstate(over="ignore", invalid="ignore"):
        factor = float(np.sum(differences * rates) / np.sum(rates * rates))
    if np.isfinite(factor) and abs(factor - 1) <= DERIVATIVE_TOLERANCE:
        return
    hint = next((text for slip, text in UNIT_SLIPS if abs(factor / slip - 1) < 0.05), "")
    raise LogError(f"{path}: the rate of change of {name} is {factor:.4g} times {rate_name} (1 expected): the "
                   f"columns disagree{'; ' + hint if hint else ''}")


def read_log(path: Path | str, convention: str = "report") -> Log:
    """The log at ``path``, in the report's theta (rad) and N m: its columns are in the
    ``convention`` "report" or "openhaptics" (HD_CURRENT_JOINT_ANGLES, rad, and joint torques,
    mN m)."""
    if convention not in ("report", "openhaptics"):
        raise LogError(f"expected 'report' or 'openhaptics', got {convention!r}", argument="convention")
    if not isinstance(path, (str, Path)):
        raise LogError(f"expected a file path, got {path!r}", argument="path")
    path = Path(path)
    lines, column = _read_table(path, LOG_COLUMNS)
    expected = "mN m" if convention == "openhaptics" else "N m"
    for name, unit in _units(lines[0][1]).items():
        plain = "".join(unit.split()).replace("*", "").replace(".", "")     # N m, Nm, N*m, N.m
        if name.startswith("tau") and plain != "".join(expected.split()):
            raise LogError(f"{path}: {name} is in {unit} (its header), the {convention} convention's torques in "
                           f"{expected}: give the convention of the log (--convention; OpenHaptics': mN m) or "
                           "convert it")
    t = column["t"]
    step = np.diff(t)
    if len(t) < 2:
        raise LogError(f"{path}: too short ({len(t)} row(s) of data; at least {MIN_DURATION} s)")
    if not (step > 0).all():
        raise LogError(f"{path}: time is not strictly increasing"
                       + (f" (line {lines[2 + int(np.argmin(step > 0))][0]})" if len(t) >= 2 else ""))
    if t[-1] - t[0] < MIN_DURATION:
        raise LogError(f"{path}: too short ({t[-1] - t[0]:.3g} s; at least {MIN_DURATION} s)")
    if uneven(step, RATE_TOLERANCE):
        raise LogError(f"{path}: not at a fixed rate (intervals {step.min():.4g}..{step.max():.4g} s)")
    theta = np.column_stack([column[f"theta{j}"] for j in (1, 2, 3)])
    tau = np.column_stack([column[f"tau{j}"] for j in (1, 2, 3)])
    if convention == "openhaptics":
        theta, tau = conventions.theta_from_openhaptics(theta), conventions.tau_from_openhaptics_torque(tau)
    return Log(t, theta, tau)


def _units(header: str) -> dict[str, str]:
    """The units a header line gives in [] (its dialect as _read_table's), by column name."""
    separator = max((",", ";", "\t"), key=header.count)
    fields = [field.strip().strip('"').strip("'") for field in header.split(separator)]
    return {_column_name(field): field.split("[", 1)[1].split("]")[0].strip() for field in fields if "[" in field}


def _column_name(text: str) -> str:
    """A header field as a column name: quotes, case, spaces and a unit in [] dropped
    ("Theta1", '"tau2"', "t [s]" as simulate writes it)."""
    name = text.strip().strip('"').strip("'").strip()
    return name.split("[")[0].strip().lower()
