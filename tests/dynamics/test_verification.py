"""check() (dynamics/verification.py): what is not a Phantom is refused, naming the call that makes one."""

import pytest

import phantom_pin
from phantom_pin import InvalidInputError


@pytest.mark.parametrize("bad, call", [("touch", "Phantom.from_model('touch')"),
                                       (phantom_pin.Description, "Phantom.from_model(model)")])
def test_check_refuses_what_is_not_a_phantom(bad, call):
    with pytest.raises(InvalidInputError) as error:
        phantom_pin.check(bad, states=1)
    assert error.value.argument == "phantom" and call in error.value.detail
