"""The constructors' refusals (dynamics/_refusals.py): what Phantom(...) is given but does not
take is refused naming the argument and the call that makes it."""

import pytest

from phantom_pin import Phantom


def test_the_plain_call_refuses_what_a_named_constructor_makes(tmp_path):
    """A model name, a folder (a Path or its text) or anything but a Description given to
    Phantom(...) is refused with InvalidInputError naming ``description`` and the call that makes
    it; from_model refuses a folder and from_folder a model name, each naming the other."""
    from phantom_pin import describe
    from phantom_pin.exceptions import InvalidInputError

    folder = tmp_path / "mine"
    folder.mkdir()
    for bad, call in (("touch", "Phantom.from_model('touch')"), ("premium_1_5", "Phantom.from_model('premium_1_5')"),
                      (folder, "Phantom.from_folder(path)"), (str(folder), "Phantom.from_folder(path)"),
                      (42, "Phantom.from_model(model)"), (describe, "Phantom.from_folder(path)")):
        with pytest.raises(InvalidInputError) as error:
            Phantom(bad)
        assert error.value.argument == "description" and call in error.value.detail, (bad, error.value.detail)
    for bad in ("nope", 3, None, folder):
        with pytest.raises(InvalidInputError) as error:
            Phantom.from_model(bad)
        assert error.value.argument == "model"
    with pytest.raises(InvalidInputError, match=r"Phantom\.from_model\('touch'\)") as error:
        Phantom.from_folder("touch")
    assert error.value.argument == "folder"
    for bad in (tmp_path / "absent", 3, None):
        with pytest.raises(InvalidInputError) as error:
            Phantom.from_folder(bad)
        assert error.value.argument == "folder"
