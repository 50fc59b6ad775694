"""The physical PHANToM around its rigid body: stops, friction, motors, encoders (Device), the
plant between two samples (Plant: dynamics, friction with stiction, stops, saturation) and a
haptic-loop simulator over it (simulate), and what the hand feels at the stylus (feel: apparent
mass, backdrive force, force capacity, workspace). Numbers: the Config's ``actuation`` and
``limits.stops`` (config/NAME/actuation.yaml and joint_limits.yaml), with their sources."""

from phantom_pin.device.device import Device
from phantom_pin.device.feel import Feel, feel
from phantom_pin.device.plant import Plant
from phantom_pin.device.run import SimulationResult
from phantom_pin.device.simulation import simulate

__all__ = ["Device", "Feel", "Plant", "SimulationResult", "feel", "simulate"]
