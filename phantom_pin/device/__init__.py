"""The physical PHANToM Premium 1.5 around the report's rigid body: stops, friction, motors,
encoders (Device) and a haptic-loop simulator (simulate). Numbers: config/actuation.yaml
and config/joint_limits.yaml ``stops``, with their sources."""

from phantom_pin.device.device import Device
from phantom_pin.device.parameters import DeviceParameters, load_device_parameters
from phantom_pin.device.simulation import SimulationResult, simulate

__all__ = ["Device", "DeviceParameters", "load_device_parameters", "SimulationResult", "simulate"]
