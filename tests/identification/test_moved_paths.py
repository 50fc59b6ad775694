"""identification's old module paths (before its stages, issue 51 item 4) answer for one release:
each imports with a DeprecationWarning naming its new path, and its names are the new module's
own objects (phantom_pin._moved.MOVED)."""

import importlib
import sys

import pytest

from phantom_pin import _moved

OLD = sorted(old for old in _moved.MOVED if old.startswith("phantom_pin.identification."))


def test_every_module_of_identification_moved_to_a_stage():
    """The 25 modules, each at identification.<stage>.<module> (its old name's last part)."""
    assert len(OLD) == 25
    for old in OLD:
        stage, _, module = _moved.MOVED[old].removeprefix("phantom_pin.identification.").partition(".")
        assert stage in ("data", "structure", "fitting", "verdict") and module == old.rpartition(".")[2], old


@pytest.mark.parametrize("old", OLD)
def test_an_old_path_warns_and_hands_on_the_new_modules_objects(old, monkeypatch):
    monkeypatch.delitem(sys.modules, old, raising=False)     # imported afresh: the warning each time
    new = importlib.import_module(_moved.MOVED[old])
    with pytest.warns(DeprecationWarning, match=f"{old} moved to {_moved.MOVED[old]}"):
        module = importlib.import_module(old)
    names = [name for name in vars(new) if not name.startswith("__")]
    assert names and all(getattr(module, name) is getattr(new, name) for name in names)
    assert getattr(module, "__all__", None) == getattr(new, "__all__", None)


def test_from_the_package_an_old_module_name_still_imports(monkeypatch):
    """``from phantom_pin.identification import io`` (the old spelling) gives the data stage's io."""
    import phantom_pin.identification

    monkeypatch.delitem(sys.modules, "phantom_pin.identification.io", raising=False)
    monkeypatch.delattr(phantom_pin.identification, "io", raising=False)
    with pytest.warns(DeprecationWarning):
        from phantom_pin.identification import io
    from phantom_pin.identification.data import io as new

    assert io.read_log is new.read_log and io.Log is new.Log
