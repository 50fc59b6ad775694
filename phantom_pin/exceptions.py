"""Errors raised by phantom_pin; every one derives from PhantomPinError.

An error about one argument carries its name in ``argument`` (``None`` otherwise), so that a
caller such as the command line can name its own option for it without parsing the text::

    raise InvalidInputError("must be positive, got -1.0 s", argument="duration")
    str(error) == "duration: must be positive, got -1.0 s"; error.detail == "must be positive, got -1.0 s"
"""

from __future__ import annotations


class PhantomPinError(Exception):
    """Base class of every error phantom_pin raises on purpose.

    ``PhantomPinError(detail, argument=None)``: with ``argument``, the message reads
    ``"<argument>: <detail>"``; ``detail`` is the text without the argument's name.
    """

    def __init__(self, detail: str = "", *, argument: str | None = None) -> None:
        self.argument = argument
        self.detail = detail
        super().__init__(detail if argument is None else f"{argument}: {detail}")

    def __reduce__(self) -> tuple:  # picklable with the keyword (multiprocessing, copy)
        return (_rebuild, (type(self), self.detail, self.argument))


def _rebuild(cls: type[PhantomPinError], detail: str, argument: str | None) -> PhantomPinError:
    return cls(detail, argument=argument)


class InvalidInputError(PhantomPinError, ValueError):
    """An argument has the wrong shape, a NaN or inf, or a value out of its domain."""


class UnreachableTargetError(InvalidInputError):
    """An inverse-kinematics target lies outside the arm's reachable workspace."""


class ParameterFileError(PhantomPinError, ValueError):
    """A parameter file is missing, malformed, or holds a non-physical value."""


class MissingDataError(InvalidInputError):
    """The model lacks the data a call needs: its motors, transmission or encoders are not
    public (the Touch), so its currents or encoder counts cannot be computed."""


class LogError(PhantomPinError, ValueError):
    """A log file is missing, malformed, or not usable for identification."""


class MissingDependencyError(PhantomPinError, ImportError):
    """An optional package a call needs is not installed; the message names the extra that
    installs it (matplotlib: ``pip install 'phantom_pin[plots]'``)."""
