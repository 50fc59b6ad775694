"""The seeded postures (config/sampling.py): inside the box, the stops and both coupled stops of
joint_limits.yaml, reaching each coupled stop; stops that keep a sliver are refused, not looped on."""

import dataclasses

import numpy as np
import pytest
import yaml

from phantom_pin import ParameterFileError, config
from phantom_pin.config.sampling import random_states


def test_random_states_refuses_a_sliver_instead_of_looping():
    """Stops that keep about 4e-7 of the box (a corner triangle 3 mrad wide): one line, no hang."""
    limits = config.read().limits
    sliver = dataclasses.replace(limits, stops=dataclasses.replace(
        limits.stops, coupled=config.CoupledStops(-4.5, 5.0)))
    with pytest.raises(ParameterFileError, match="coupled stops .* keep too little of the joint box"):
        random_states(sliver, 100, seed=0)
    theta = random_states(limits, 2000, seed=0)[0]  # the shipped stops: inside
    assert np.all(theta[:, 1] - theta[:, 2] <= limits.stops.coupled.theta2_minus_theta3_max)
    assert np.all(theta[:, 2] - theta[:, 1] <= limits.stops.coupled.theta3_minus_theta2_max)


@pytest.mark.parametrize("name", config.models())
def test_sampled_postures_fill_exactly_the_yamls_limits(name):
    """20000 seeded postures against joint_limits.yaml read here: inside the box, the stops and
    both coupled stops, and reaching each coupled stop to 0.02 rad (so a swapped or tightened
    coupled limit is seen)."""
    data = yaml.safe_load((config.MODELS[name].config / "joint_limits.yaml").read_text())
    joints = ("joint1", "joint2", "joint3")
    lower = np.maximum([data[j]["lower"] for j in joints], [data["stops"][j]["lower"] for j in joints])
    upper = np.minimum([data[j]["upper"] for j in joints], [data["stops"][j]["upper"] for j in joints])
    forward, backward = data["stops"]["theta2_minus_theta3_max"], data["stops"]["theta3_minus_theta2_max"]
    theta = random_states(config.read(name).limits, 20000, seed=5)[0]
    assert (theta >= lower).all() and (theta <= upper).all()
    difference = theta[:, 1] - theta[:, 2]
    assert difference.max() <= forward and -difference.max() >= -forward
    assert (-difference).max() <= backward
    assert difference.max() > forward - 0.02 and (-difference).max() > backward - 0.02
