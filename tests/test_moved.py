"""The modules that moved keep their old paths for one release (phantom_pin._moved): each old
path imports with a DeprecationWarning naming the new one, in a fresh interpreter, and hands on
the new module's very objects; a name the new module lacks is an AttributeError."""

import importlib
import subprocess
import sys

import pytest

from phantom_pin import _moved


@pytest.mark.parametrize("old", sorted(_moved.MOVED))
def test_an_old_path_warns_and_hands_on_the_new_modules_objects(old):
    new = _moved.MOVED[old]
    script = (f"import warnings, importlib\nwarnings.simplefilter('error')\n"
              f"try:\n    importlib.import_module({old!r})\nexcept DeprecationWarning as w:\n    print(w)\n")
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert result.returncode == 0 and result.stdout.strip() == f"{old} moved to {new}; the old path works until " \
        "the next release (CHANGELOG.md)", result.stdout + result.stderr
    target = importlib.import_module(new)
    with pytest.warns(DeprecationWarning, match=f"{old} moved to {new}"):
        sys.modules.pop(old, None)
        module = importlib.import_module(old)
    names = getattr(target, "__all__", None) or [n for n in vars(target) if not n.startswith("_")]
    assert names and all(getattr(module, name) is getattr(target, name) for name in names)
    with pytest.raises(AttributeError):
        module.no_such_name  # noqa: B018


def test_a_moved_root_module_is_an_attribute_of_the_package_and_nothing_else_is():
    import phantom_pin

    with pytest.warns(DeprecationWarning, match="phantom_pin.drivers moved to phantom_pin.interfaces.conventions"):
        sys.modules.pop("phantom_pin.drivers", None)
        vars(phantom_pin).pop("drivers", None)
        drivers = phantom_pin.drivers
    assert drivers.theta_from_openhaptics is importlib.import_module(
        "phantom_pin.interfaces.conventions").theta_from_openhaptics
    with pytest.raises(AttributeError, match="no attribute 'no_such_module'"):
        phantom_pin.no_such_module  # noqa: B018


def test_every_new_path_exists_and_no_old_path_is_a_file():
    from pathlib import Path

    root = Path(_moved.__file__).resolve().parent.parent
    for old, new in _moved.MOVED.items():
        importlib.import_module(new)
        assert not (root / (old.replace(".", "/") + ".py")).exists(), old
