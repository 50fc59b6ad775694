"""Errors raised by phantom_pin; every one derives from PhantomPinError."""


class PhantomPinError(Exception):
    """Base class of every error phantom_pin raises on purpose."""


class InvalidInputError(PhantomPinError, ValueError):
    """An argument has the wrong shape, a NaN or inf, or a value out of its domain."""


class UnreachableTargetError(InvalidInputError):
    """An inverse-kinematics target lies outside the arm's reachable workspace."""


class ParameterFileError(PhantomPinError, ValueError):
    """A parameter file is missing, malformed, or holds a non-physical value."""
