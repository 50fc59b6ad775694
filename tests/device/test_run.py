"""What the device's two plants share about a run (device/run.py): simulate and simulate_mujoco
name the bad argument in the error's field."""

import pytest

from phantom_pin import InvalidInputError, simulate
from phantom_pin.device.mujoco_plant import simulate_mujoco


@pytest.mark.parametrize("arguments, name", [
    ({"duration": -1.0}, "duration"),
    ({"rate": float("nan")}, "rate"),
    ({"substeps": 0}, "substeps"),
    ({"friction": "yes"}, "friction"),
    ({"saturation": "stall"}, "saturation"),
    ({"controller": lambda t, q, v: [1.0, 2.0]}, "controller"),
    ({"theta0": [20.0, 0.0, 0.0]}, "theta0"),
    ({"progress": 3}, "progress"),
])
def test_simulate_names_the_bad_argument_in_the_field(arguments, name):
    settings = {"theta0": [0.0, 0.3, 0.4], "duration": 0.01} | arguments
    with pytest.raises(InvalidInputError) as raised:
        simulate(settings.pop("theta0"), settings.pop("duration"), **settings)
    assert raised.value.argument == name and str(raised.value).startswith(f"{name}: ")


@pytest.mark.parametrize("arguments, name", [({"rate": 333.0}, "rate"), ({"timestep": 3e-4}, "timestep"),
                                             ({"timestep": -1.0}, "timestep"), ({"duration": 0.0}, "duration")])
def test_simulate_mujoco_names_the_bad_argument_in_the_field(arguments, name):
    """MuJoCo steps 1 ms by default: 333 Hz and 1 kHz at 0.3 ms are no whole number of steps."""
    settings = {"duration": 0.01} | arguments
    with pytest.raises(InvalidInputError) as raised:
        simulate_mujoco([0.0, 0.3, 0.4], settings.pop("duration"), **settings)
    assert raised.value.argument == name and str(raised.value).startswith(f"{name}: ")
