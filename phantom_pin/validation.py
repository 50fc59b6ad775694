"""Shape and finiteness checks shared by the closed-form and Pinocchio APIs."""

from __future__ import annotations

import numpy as np

from phantom_pin.exceptions import InvalidInputError


def as_states(value: object, name: str, width: int = 3) -> tuple[np.ndarray, bool]:
    """Return ``value`` as a float array of shape (width,) or (..., width).

    The second result is True when ``value`` carried leading (batch) axes.
    Raises InvalidInputError naming ``name`` on a wrong shape, a non-numeric
    value, NaN or inf.
    """
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as error:
        raise InvalidInputError(f"{name}: expected numbers, got {value!r}") from error
    if array.ndim == 0 or array.shape[-1] != width:
        raise InvalidInputError(
            f"{name}: expected shape ({width},) or (N, {width}), got {array.shape}")
    if array.size == 0:
        raise InvalidInputError(f"{name}: expected at least one state, got shape {array.shape}")
    if not np.isfinite(array).all():
        raise InvalidInputError(f"{name}: contains NaN or inf")
    return array, array.ndim > 1


def as_state(value: object, name: str) -> np.ndarray:
    """Return ``value`` as one float vector of shape (3,); as_states' checks, and no batch."""
    array, batch = as_states(value, name)
    if batch:
        raise InvalidInputError(f"{name}: expected one vector, shape (3,), got {array.shape}")
    return array


def same_batch(names: tuple[str, ...], *arrays: np.ndarray) -> None:
    """Raise InvalidInputError unless all ``arrays`` have the same shape."""
    shapes = {a.shape for a in arrays}
    if len(shapes) > 1:
        listed = ", ".join(f"{n} {a.shape}" for n, a in zip(names, arrays))
        raise InvalidInputError(f"arguments must have the same shape: {listed}")
