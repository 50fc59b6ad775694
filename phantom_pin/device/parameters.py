"""The physical device's numbers: motor, encoder, friction (actuation.yaml) and the
mechanical stops (joint_limits.yaml ``stops``), each section with its source."""

from __future__ import annotations

import dataclasses
from pathlib import Path

from phantom_pin.exceptions import ParameterFileError
from phantom_pin.parameters import Config, coupled_stops, read_config
from phantom_pin.paths import CONFIG_DIR

_JOINTS = ("joint1", "joint2", "joint3")
#: The ``sources`` entries each file must have (a non-empty text per section).
_SOURCES = {"actuation_file": ("transmission_ratio", "motor", "encoder", "friction"),
            "joint_limits_file": ("stops",)}


@dataclasses.dataclass(frozen=True)
class DeviceParameters:
    """Numbers of the physical PHANToM Premium 1.5 beyond the rigid body, SI units, radians.

    Motor (maxon RE 25 118743, at the motor shaft): ``max_continuous_torque``,
    ``stall_torque`` (N m), ``max_continuous_current``, ``stall_current`` (A),
    ``torque_constant`` (N m/A), ``terminal_resistance`` (Ohm), ``max_speed`` (rad/s).
    Encoder: ``cycles_per_revolution`` of the motor shaft, ``counts_per_cycle``
    (quadrature decoding). Friction at each joint: ``viscous`` (N m s/rad), ``coulomb``
    (N m), ``smoothing_speed`` (rad/s). Stops (rad, the report's theta):
    ``stop_lower``, ``stop_upper`` per joint, ``theta2_minus_theta3_max`` and
    ``theta3_minus_theta2_max`` (the parallelogram), ``stop_stiffness`` (N m/rad) and
    ``stop_damping`` (N m s/rad). ``sources``: section name -> where its numbers come from.
    """

    max_continuous_torque: float
    max_continuous_current: float
    stall_torque: float
    stall_current: float
    torque_constant: float
    terminal_resistance: float
    max_speed: float
    cycles_per_revolution: float
    counts_per_cycle: float
    viscous: float
    coulomb: float
    smoothing_speed: float
    stop_lower: tuple[float, float, float]
    stop_upper: tuple[float, float, float]
    theta2_minus_theta3_max: float
    theta3_minus_theta2_max: float
    stop_stiffness: float
    stop_damping: float
    sources: dict[str, str]


def _sources(config: Config, arg: str) -> dict[str, str]:
    path, node = config.paths[arg], config.data[arg].get("sources")
    if not isinstance(node, dict):
        raise ParameterFileError(f"{path}: missing key sources (a mapping: section -> source)")
    for section in _SOURCES[arg]:
        if not isinstance(node.get(section), str) or not node[section].strip():
            raise ParameterFileError(f"{path}: sources.{section} must be a non-empty text")
    return {section: node[section] for section in _SOURCES[arg]}


def load_device_parameters(config_dir: Path | str = CONFIG_DIR) -> DeviceParameters:
    """Read actuation.yaml and joint_limits.yaml of ``config_dir`` (device_parameters_from)."""
    return device_parameters_from(read_config(config_dir))


def device_parameters_from(config: Config) -> DeviceParameters:
    """The device numbers of ``config`` (actuation.yaml and joint_limits.yaml ``stops``);
    ParameterFileError naming the file and the key of a missing or non-physical number."""
    lim_path = config.paths["joint_limits_file"]

    def act(*keys: str, positive: bool = True) -> float:
        return config.number("actuation_file", *keys, positive=positive)

    def lim(*keys: str, positive: bool = False) -> float:
        return config.number("joint_limits_file", *keys, positive=positive)

    def non_negative(arg: str, *keys: str) -> float:
        value = config.number(arg, *keys)
        if value < 0:
            raise ParameterFileError(f"{config.paths[arg]}: {'.'.join(keys)} must not be negative, got {value!r}")
        return value

    lower = tuple(lim("stops", j, "lower") for j in _JOINTS)
    upper = tuple(lim("stops", j, "upper") for j in _JOINTS)
    for joint, lo, hi in zip(_JOINTS, lower, upper):
        if lo >= hi:
            raise ParameterFileError(f"{lim_path}: stops.{joint}.lower must be below stops.{joint}.upper")
    forward, backward = coupled_stops(config, lower, upper)
    return DeviceParameters(
        max_continuous_torque=act("motor", "max_continuous_torque"),
        max_continuous_current=act("motor", "max_continuous_current"),
        stall_torque=act("motor", "stall_torque"),
        stall_current=act("motor", "stall_current"),
        torque_constant=act("motor", "torque_constant"),
        terminal_resistance=act("motor", "terminal_resistance"),
        max_speed=act("motor", "max_speed"),
        cycles_per_revolution=act("encoder", "cycles_per_revolution"),
        counts_per_cycle=act("encoder", "counts_per_cycle"),
        viscous=non_negative("actuation_file", "friction", "viscous"),
        coulomb=non_negative("actuation_file", "friction", "coulomb"),
        smoothing_speed=act("friction", "smoothing_speed"),
        stop_lower=lower,
        stop_upper=upper,
        theta2_minus_theta3_max=forward,
        theta3_minus_theta2_max=backward,
        stop_stiffness=lim("stops", "stiffness", positive=True),
        stop_damping=non_negative("joint_limits_file", "stops", "damping"),
        sources={**_sources(config, "actuation_file"), **_sources(config, "joint_limits_file")},
    )
