"""Errors raised by phantom_pin; every one derives from PhantomPinError."""


class PhantomPinError(Exception):
    """Base class of every error phantom_pin raises on purpose."""


class InvalidInputError(PhantomPinError, ValueError):
    """An argument has the wrong shape, a NaN or inf, or a value out of its domain."""


class UnreachableTargetError(InvalidInputError):
    """An inverse-kinematics target lies outside the arm's reachable workspace."""


class ParameterFileError(PhantomPinError, ValueError):
    """A parameter file is missing, malformed, or holds a non-physical value."""


class MissingDataError(InvalidInputError):
    """The model lacks the data a call needs: its motors, transmission or encoders are not
    public (the Touch), so its currents or encoder counts cannot be computed."""
