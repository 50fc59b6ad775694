"""config.read (config/load.py): an override is checked like the file, before any model is built."""

import pytest

from phantom_pin import ParameterFileError, describe


def test_negative_friction_is_refused_as_an_override_before_any_model():
    """Before, Phantom(describe(overrides={"actuation.friction.viscous": -5e-4})) raised
    Pinocchio's raw "min_dry_friction" traceback and `urdf --set` wrote damping="-1"."""
    with pytest.raises(ParameterFileError,
                       match="after the overrides, .*actuation.yaml: friction.viscous must not be negative"):
        describe(overrides={"actuation.friction.viscous": -5e-4})
