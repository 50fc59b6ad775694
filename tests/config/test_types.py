"""The typed Config (config/types.py): the shipped configuration is frozen or read-only throughout."""

import dataclasses

import pytest

from phantom_pin import Device
from phantom_pin.description.build import shipped


def test_the_shipped_configuration_cannot_be_changed():
    """Before, shipped().config.data was a mutable dict: a change leaked into every later
    Device() in the process. Now every part is frozen or read-only."""
    c = shipped().config
    with pytest.raises(dataclasses.FrozenInstanceError):
        c.actuation.friction.viscous = 1.0
    with pytest.raises(dataclasses.FrozenInstanceError):
        c.links["forearm_link"].mass = 1.0
    with pytest.raises(TypeError):
        c.links["forearm_link"] = None
    with pytest.raises(TypeError):
        c.visual["colors"]["arm"] = [0, 0, 0, 1]
    with pytest.raises(TypeError):
        c.sources["friction"] = "mine"
    assert Device().config.actuation.friction.viscous == (5.0e-4,) * 3
