"""The error base: an argument's name travels in a field, and survives pickling."""

import pickle

import pytest

from phantom_pin.exceptions import InvalidInputError, MissingDataError, ParameterFileError, PhantomPinError


@pytest.mark.parametrize("cls", [PhantomPinError, InvalidInputError, MissingDataError, ParameterFileError])
def test_argument_field_and_message(cls):
    error = cls("must be positive, got -1 s", argument="duration")
    assert (error.argument, error.detail) == ("duration", "must be positive, got -1 s")
    assert str(error) == "duration: must be positive, got -1 s"
    plain = cls("no argument")
    assert (plain.argument, plain.detail, str(plain)) == (None, "no argument", "no argument")
    copy = pickle.loads(pickle.dumps(error))
    assert type(copy) is cls and (copy.argument, copy.detail, str(copy)) == ("duration", error.detail, str(error))


def test_value_errors():
    assert issubclass(InvalidInputError, ValueError) and issubclass(ParameterFileError, ValueError)
