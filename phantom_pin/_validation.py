"""Checks shared by the closed-form and Pinocchio APIs and the command line: shapes and
finiteness of inputs and results, angle wrapping, output paths."""

from __future__ import annotations

import os
from collections.abc import Iterable
from pathlib import Path
from typing import cast

import numpy as np

from phantom_pin.exceptions import InvalidInputError, PhantomPinError


def _has_bool(values: object) -> bool:
    """Whether a (nested) sequence holds a boolean anywhere: NumPy reads [1.0, True] as floats."""
    stack: list[Iterable[object]] = [cast("Iterable[object]", values)]
    while stack:
        for item in stack.pop():
            if isinstance(item, (bool, np.bool_)):
                return True
            if isinstance(item, (list, tuple, np.ndarray)):
                stack.append(item)
    return False


def as_states(value: object, name: str, width: int = 3) -> tuple[np.ndarray, bool]:
    """Return ``value`` as a float array of shape (width,) or (..., width): one state, or a
    batch with any number of leading axes (each result keeps them).

    The second result is True when ``value`` carried leading (batch) axes.
    Raises InvalidInputError naming ``name`` on a wrong or ragged shape, a non-numeric,
    boolean or complex value, NaN or inf.
    """
    try:
        array = np.asarray(value)
        if array.dtype.kind == "c":
            raise InvalidInputError("expected real numbers, got complex values", argument=name)
        if array.dtype.kind == "b" or ((array.dtype.kind == "O" or isinstance(value, (list, tuple)))
                                       and _has_bool(value if array.dtype.kind != "O" else array.flat)):
            raise InvalidInputError("expected real numbers, got booleans", argument=name)
        if array.dtype.kind not in "iufO":  # strings, bytes, dates
            raise TypeError(array.dtype)
        array = array.astype(float, copy=False)
    except (TypeError, ValueError) as error:
        if isinstance(error, InvalidInputError):
            raise
        raise InvalidInputError(f"expected numbers, got {value!r}", argument=name) from error
    if array.ndim == 0 or array.shape[-1] != width:
        raise InvalidInputError(f"expected shape ({width},) or (..., {width}), got {array.shape}", argument=name)
    if array.size == 0:
        raise InvalidInputError(f"expected at least one state, got shape {array.shape}", argument=name)
    if not np.isfinite(array).all():
        raise InvalidInputError("contains NaN or inf", argument=name)
    return array, array.ndim > 1


def as_state(value: object, name: str) -> np.ndarray:
    """Return ``value`` as one float vector of shape (3,); as_states' checks, and no batch."""
    array, batch = as_states(value, name)
    if batch:
        raise InvalidInputError(f"expected one vector, shape (3,), got {array.shape}", argument=name)
    return array


def same_batch(names: tuple[str, ...], *arrays: np.ndarray) -> None:
    """Raise InvalidInputError unless all ``arrays`` have the same shape."""
    shapes = {a.shape for a in arrays}
    if len(shapes) > 1:
        listed = ", ".join(f"{n} {a.shape}" for n, a in zip(names, arrays))
        raise InvalidInputError(f"arguments must have the same shape: {listed}")


def finite_result(result: np.ndarray, names: str) -> np.ndarray:
    """Return ``result``; raise InvalidInputError naming the inputs ``names`` if it holds a
    NaN or inf, which finite inputs produce only by overflowing (for example rates of
    1e200 rad/s, whose squares exceed the largest float)."""
    if not np.isfinite(result).all():
        raise InvalidInputError("too large, the result overflows to inf or NaN", argument=names)
    return result


def within_box(theta: object, lower: np.ndarray, upper: np.ndarray) -> bool | np.ndarray:
    """True where ``theta`` (rad), shape (3,) or (..., 3), satisfies lower <= theta <= upper
    in every joint: a bool for one state, a bool array of shape (...) for a batch."""
    q, batch = as_states(theta, "theta")
    inside = np.all((lower <= q) & (q <= upper), axis=-1)
    return inside if batch else bool(inside)


def wrap_angle(angle: np.ndarray) -> np.ndarray:
    """Angles (rad) mapped into (-pi, pi]; angles already inside are returned unchanged."""
    outside = (angle > np.pi) | (angle <= -np.pi)
    return np.where(outside, np.pi - (np.pi - angle) % (2 * np.pi), angle)


def output_path(path: str | os.PathLike[str], force: bool, name: str, force_hint: str = "force=True",
                error: type[PhantomPinError] = InvalidInputError) -> Path:
    """``path`` as the Path of a file to write, checked before any work: the one output check of
    every writer (the library's and the command line's). Raise ``error`` naming ``name`` if it is
    a folder, if its folder does not exist or cannot be written in, or if it exists and not
    ``force`` (``force_hint`` says how to ask for overwriting). A path that exists and is no
    regular file (/dev/null, a pipe) is written in place: its folder is not asked."""
    output = Path(path)
    if output.is_dir():
        raise error(f"{output} is a folder; name a file", argument=name)
    if not output.parent.is_dir():
        raise error(f"folder {output.parent} does not exist", argument=name)
    if (output.is_file() or not output.exists()) and not os.access(output.resolve().parent, os.W_OK):
        raise error(f"cannot write in {output.resolve().parent}", argument=name)
    if output.exists() and not force:
        raise error(f"{output} exists; use {force_hint} to overwrite it", argument=name)
    return output


def fixed_rate(t: np.ndarray) -> float:
    """The rate (Hz) of times ``t`` (s, (N,), N >= 2) sampled at a fixed rate: (N - 1) / (t[-1] - t[0])."""
    return float((len(t) - 1) / (t[-1] - t[0]))


def uneven(step: np.ndarray, tolerance: float) -> bool:
    """Whether the intervals ``step`` (s) stray from their mean by more than ``tolerance`` of it."""
    return bool(np.abs(step - step.mean()).max() > tolerance * step.mean())
