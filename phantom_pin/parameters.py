"""The report's physical parameters, read from the description's config/*.yaml files."""

from __future__ import annotations

import dataclasses
import math
import os
import re
from pathlib import Path
from typing import Callable, Sequence

import numpy as np
import yaml

from phantom_pin.exceptions import InvalidInputError, ParameterFileError
from phantom_pin.paths import CONFIG_DIR

#: The parameter files of robots/phantom_description/config, by xacro argument name.
PARAMETER_FILES = {
    "kinematics_file": "kinematics.yaml",
    "physical_parameters_file": "physical_parameters.yaml",
    "actuation_file": "actuation.yaml",
    "joint_limits_file": "joint_limits.yaml",
    "visual_parameters_file": "visual_parameters.yaml",
    "mjcf_file": "mjcf.yaml",
}

#: Largest |joint limit| (rad): a revolute joint's range beyond one turn each way repeats
#: postures and describes no stop of this arm (mahilab's widest stop is 3.74 rad).
JOINT_LIMIT_BOUND = 2 * math.pi


@dataclasses.dataclass(frozen=True)
class Parameters:
    """Numbers of the report, SI units, named as in the report's appendix.

    Lengths l1, l2, l3 (m, eqs 29-31), l5, l6 (m, COM offsets of BE and DF, eqs 63,
    73); masses m* (kg); inertias I* (kg m^2) in the report's segment axes: A and C
    about their COM, BE and DF about the shoulder, Ibaseyy about axis 1. As in the
    report, Ibexx, Idfxx and Ibaseyy include the motors' reflected rotor inertia
    ``rotor_inertia * ratio**2``. g is gravity (m/s^2), pointing along the report's -y.
    ``lower`` and ``upper`` are the joint position limits (rad) of theta1..theta3: the
    URDF's box. ``coupled`` = (max of theta2 - theta3, max of theta3 - theta2) (rad): the
    parallelogram's stops, which the box cannot express (joint_limits.yaml ``stops``).
    """

    l1: float
    l2: float
    l3: float
    l5: float
    l6: float
    g: float
    ma: float
    Iaxx: float
    Iayy: float
    Iazz: float
    mc: float
    Icxx: float
    Icyy: float
    Iczz: float
    mbe: float
    Ibexx: float
    Ibeyy: float
    Ibezz: float
    mdf: float
    Idfxx: float
    Idfyy: float
    Idfzz: float
    Ibaseyy: float
    rotor_inertia: float
    ratios: tuple[float, float, float]
    lower: tuple[float, float, float]
    upper: tuple[float, float, float]
    coupled: tuple[float, float]

    @property
    def armature(self) -> tuple[float, float, float]:
        """Reflected rotor inertia of each joint, rotor_inertia * ratio^2 (kg m^2)."""
        return tuple(self.rotor_inertia * r**2 for r in self.ratios)


class _Loader(yaml.SafeLoader):
    """PyYAML's safe loader, which also reads 1e-6 and 1.0e6 as numbers.

    PyYAML follows YAML 1.1, whose floats need a dot and a signed exponent: it reads
    ``1e-6`` and ``1.0e6`` as strings (``1.0e-6`` and ``1.0e+6`` as numbers). YAML 1.2
    reads all four as numbers, and so does this loader.
    """


_Loader.add_implicit_resolver(
    "tag:yaml.org,2002:float", re.compile(r"^[-+]?[0-9][0-9_]*(?:\.[0-9_]*)?[eE][-+]?[0-9]+$"),
    list("-+0123456789"))


def _read(path: Path) -> dict:
    """The mapping in the YAML file ``path``; ParameterFileError naming it (one line) if it
    cannot be read, is not UTF-8 text, is not valid YAML or is not a mapping."""
    try:
        with open(path, encoding="utf-8") as stream:
            data = yaml.load(stream, Loader=_Loader)
    except OSError as error:
        raise ParameterFileError(f"{path}: cannot read ({error.strerror})") from error
    except UnicodeDecodeError as error:
        raise ParameterFileError(f"{path}: not a text file (not UTF-8 at byte {error.start})") from error
    except yaml.YAMLError as error:
        mark = getattr(error, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        problem = getattr(error, "problem", None) or " ".join(str(error).split())
        raise ParameterFileError(f"{path}: not valid YAML{where}: {problem}") from error
    if not isinstance(data, dict):
        raise ParameterFileError(f"{path}: expected a mapping at the top level")
    return data


def _is_number(value: object) -> bool:
    """True for an int or float that is not a bool (YAML's true/false)."""
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _number(data: dict, path: Path, *keys: str, positive: bool = False) -> float:
    node: object = data
    for depth, key in enumerate(keys):
        if not isinstance(node, dict) or key not in node:
            raise ParameterFileError(f"{path}: missing key {'.'.join(keys[:depth + 1])}")
        node = node[key]
    if not _is_number(node) or not math.isfinite(node):
        raise ParameterFileError(f"{path}: {'.'.join(keys)} must be a finite number, got {node!r}")
    if positive and node <= 0:
        raise ParameterFileError(f"{path}: {'.'.join(keys)} must be positive, got {node!r}")
    return float(node)


def parameter_paths(config_dir: Path | str = CONFIG_DIR, **overrides: Path | str) -> dict[str, Path]:
    """Paths of the five parameter files: ``config_dir``'s, or ``overrides`` by xacro arg name."""
    for name, value in {"config_dir": config_dir, **overrides}.items():
        if not isinstance(value, (str, os.PathLike)):
            raise InvalidInputError(f"{name}: expected a path (str or os.PathLike), got {value!r}")
    unknown = set(overrides) - set(PARAMETER_FILES)
    if unknown:
        raise ParameterFileError(f"unknown parameter file argument(s): {sorted(unknown)}")
    paths = {arg: Path(config_dir) / name for arg, name in PARAMETER_FILES.items()}
    paths.update({arg: Path(p) for arg, p in overrides.items()})
    return paths


@dataclasses.dataclass(frozen=True)
class Config:
    """The parameter files of one configuration, each read once: ``paths`` and ``data`` (the
    YAML mappings, with any overrides applied) by xacro argument name (PARAMETER_FILES).
    ``overridden`` tells whether overrides were applied. Treat ``data`` as read-only."""

    paths: dict[str, Path]
    data: dict[str, dict]
    overridden: bool = False

    def number(self, arg: str, *keys: str, positive: bool = False) -> float:
        """The number at ``keys`` in the file ``arg``; ParameterFileError naming both."""
        try:
            return _number(self.data[arg], self.paths[arg], *keys, positive=positive)
        except ParameterFileError as error:
            if self.overridden:
                raise ParameterFileError(f"after the overrides, {error}") from None
            raise


def read_config(config_dir: Path | str = CONFIG_DIR, overrides: dict[str, object] | None = None,
                **files: Path | str) -> Config:
    """Read the parameter files (``config_dir``'s, or ``files`` by xacro argument name as in
    parameter_paths) once each, and apply ``overrides``.

    Override keys are dotted paths into the files ("l1", "segment_a.mass", "joint2.upper"),
    optionally qualified by the file's stem ("actuation.motor.rotor_inertia"); an
    unqualified key must exist in exactly one file. Each must name a number, and each
    value must be a finite number in the units of that file (SI, radians).
    Raises ParameterFileError naming the file, or the key.
    """
    paths = parameter_paths(config_dir, **files)
    data = {arg: _read(path) for arg, path in paths.items()}
    stems = {Path(name).stem: arg for arg, name in PARAMETER_FILES.items()}
    for key, value in (overrides or {}).items():
        parts = str(key).split(".")
        if parts[0] in stems and len(parts) > 1:  # qualified: "actuation.motor.rotor_inertia"
            holders, parts = [stems[parts[0]]], parts[1:]
        else:
            holders = [arg for arg, document in data.items() if parts[0] in document]
        if not holders:
            raise ParameterFileError(f"{key}: no parameter file has the key {parts[0]!r}")
        if len(holders) > 1:
            names = [PARAMETER_FILES[arg] for arg in holders]
            raise ParameterFileError(f"{key}: {' and '.join(names)} both have {parts[0]!r}; "
                                     f"qualify it, e.g. {Path(names[0]).stem}.{key}")
        name = PARAMETER_FILES[holders[0]]
        if parts[0] not in data[holders[0]]:
            raise ParameterFileError(f"{key}: {name} has no key {parts[0]!r}")
        node: object = data[holders[0]]
        for part in parts[:-1]:
            node = node.get(part) if isinstance(node, dict) else None
        current = node.get(parts[-1]) if isinstance(node, dict) else None
        if not _is_number(current):
            raise ParameterFileError(f"{key}: not a number in {name}, cannot override it")
        if not _is_number(value) or not math.isfinite(value):
            raise ParameterFileError(f"{key}: expected a finite number, got {value!r}")
        node[parts[-1]] = float(value)
    return Config(paths, data, bool(overrides))


def write_config(config: Config, destination: Path | str) -> Path:
    """Write the parameter files of ``config`` into the folder ``destination`` under their
    usual names and return it. The copies hold plain YAML numbers that any YAML 1.1 reader
    (xacro's) reads as numbers, whatever form the originals use; comments are not copied."""
    destination = Path(destination)
    for arg, name in PARAMETER_FILES.items():
        with open(destination / name, "w", encoding="utf-8") as stream:
            yaml.safe_dump(config.data[arg], stream, sort_keys=False)
    return destination


def load_parameters(config_dir: Path | str = CONFIG_DIR, **files: Path | str) -> Parameters:
    """Read and check the parameter files; raise ParameterFileError naming file and key."""
    return parameters_from(read_config(config_dir, **files))


def parameters_from(config: Config) -> Parameters:
    """The report's numbers of ``config``, checked; ParameterFileError naming file and key."""
    lim_path = config.paths["joint_limits_file"]

    def kin(*keys: str, positive: bool = True) -> float:
        return config.number("kinematics_file", *keys, positive=positive)

    def phys(*keys: str, positive: bool = True) -> float:
        return config.number("physical_parameters_file", *keys, positive=positive)

    def act(*keys: str) -> float:
        return config.number("actuation_file", *keys, positive=True)

    def lim(*keys: str) -> float:
        return config.number("joint_limits_file", *keys)

    def inertia(segment: str, axis: str) -> float:
        return phys(segment, "inertia", axis)

    joints = ("joint1", "joint2", "joint3")
    lower = tuple(lim(j, "lower") for j in joints)
    upper = tuple(lim(j, "upper") for j in joints)
    prefix = "after the overrides, " if config.overridden else ""
    for joint, lo, hi in zip(joints, lower, upper):
        for side, value in (("lower", lo), ("upper", hi)):
            if abs(value) > JOINT_LIMIT_BOUND:
                raise ParameterFileError(f"{prefix}{lim_path}: {joint}.{side} must be within one turn "
                                         f"(|limit| <= 2 pi rad), got {value!r}")
        if lo >= hi:
            raise ParameterFileError(f"{prefix}{lim_path}: {joint}.lower must be below {joint}.upper")
    return Parameters(
        l1=kin("l1"), l2=kin("l2"), l3=kin("l3"),
        l5=phys("segment_be", "com", positive=False),
        l6=phys("segment_df", "com", positive=False),
        g=phys("gravity"),
        ma=phys("segment_a", "mass"),
        Iaxx=inertia("segment_a", "xx"), Iayy=inertia("segment_a", "yy"),
        Iazz=inertia("segment_a", "zz"),
        mc=phys("segment_c", "mass"),
        Icxx=inertia("segment_c", "xx"), Icyy=inertia("segment_c", "yy"),
        Iczz=inertia("segment_c", "zz"),
        mbe=phys("segment_be", "mass"),
        Ibexx=inertia("segment_be", "xx"), Ibeyy=inertia("segment_be", "yy"),
        Ibezz=inertia("segment_be", "zz"),
        mdf=phys("segment_df", "mass"),
        Idfxx=inertia("segment_df", "xx"), Idfyy=inertia("segment_df", "yy"),
        Idfzz=inertia("segment_df", "zz"),
        Ibaseyy=phys("segment_g", "inertia_yy"),
        rotor_inertia=act("motor", "rotor_inertia"),
        ratios=tuple(act("transmission_ratio", j) for j in joints),
        lower=lower,
        upper=upper,
        coupled=coupled_stops(config, lower, upper),
    )


def coupled_stops(config: Config, lower: Sequence[float], upper: Sequence[float]) -> tuple[float, float]:
    """The parallelogram's coupled stops of joint_limits.yaml ``stops``: (max of theta2 -
    theta3, max of theta3 - theta2) (rad), read and checked once for Parameters and the
    device. ParameterFileError unless -backward <= theta2 - theta3 <= forward is an open
    interval that overlaps the range of theta2 - theta3 over the box ``lower``..``upper``
    (rad, theta1..theta3): outside it no posture satisfies both."""
    path = config.paths["joint_limits_file"]
    prefix = "after the overrides, " if config.overridden else ""
    forward = config.number("joint_limits_file", "stops", "theta2_minus_theta3_max")
    backward = config.number("joint_limits_file", "stops", "theta3_minus_theta2_max")
    if forward + backward <= 0:
        raise ParameterFileError(f"{prefix}{path}: stops.theta2_minus_theta3_max + "
                                 f"stops.theta3_minus_theta2_max must be positive (an open interval), "
                                 f"got {forward!r} + {backward!r}")
    low, high = lower[1] - upper[2], upper[1] - lower[2]
    if forward <= low or -backward >= high:
        raise ParameterFileError(
            f"{prefix}{path}: the coupled stops {-backward:.4f} <= theta2 - theta3 <= {forward:.4f} rad "
            f"leave no posture in the box, where theta2 - theta3 spans {low:.4f} .. {high:.4f} rad")
    return forward, backward


#: Rounds of rejection sampling before sample_inside gives up: enough when the limits keep
#: more than about 1/2000 of the box.
_SAMPLING_ROUNDS = 1000


def sample_inside(rng: np.random.Generator, lower: Sequence[float], upper: Sequence[float],
                  inside: Callable[[np.ndarray], np.ndarray], n: int, draws: int, limits: str) -> np.ndarray:
    """``n`` postures (rad), (n, 3), uniform in the box ``lower``..``upper`` where ``inside``
    (a bool per row of an (m, 3) array) holds: rejection sampling, ``draws`` per round.
    ParameterFileError naming ``limits`` if they keep too little of the box."""
    theta = np.empty((0, 3))
    for _ in range(_SAMPLING_ROUNDS):
        draw = rng.uniform(lower, upper, (draws, 3))
        theta = np.concatenate([theta, draw[inside(draw)]])
        if len(theta) >= n:
            return theta[:n]
    raise ParameterFileError(f"{limits} keep too little of the joint box to draw {n} postures "
                             f"({len(theta)} in {_SAMPLING_ROUNDS} rounds)")


def random_states(params: Parameters, n: int,
                  seed: int | np.random.Generator) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``n`` seeded states (theta, dtheta, ddtheta), each (n, 3): theta uniform inside the
    joint limits (rad): the box and the coupled stops (``params.coupled``); rates and
    accelerations normal with standard deviations 2 rad/s and 20 rad/s^2. ``seed`` may be
    a Generator, to draw a long sequence in chunks."""
    rng = np.random.default_rng(seed)
    forward, backward = params.coupled
    theta = sample_inside(  # the shipped stops keep 55 % of the box
        rng, params.lower, params.upper,
        lambda t: (t[:, 1] - t[:, 2] <= forward) & (t[:, 2] - t[:, 1] <= backward), n, 2 * n + 16,
        f"joint_limits.yaml: the coupled stops (stops.theta2_minus_theta3_max {forward!r}, "
        f"stops.theta3_minus_theta2_max {backward!r})")
    return theta, rng.normal(0, 2, (n, 3)), rng.normal(0, 20, (n, 3))


def read_overrides(path: Path | str) -> dict[str, float]:
    """Read a YAML file of parameter overrides into dotted keys.

    Nested mappings and dotted keys are equivalent: ``segment_a: {mass: 0.03}`` and
    ``segment_a.mass: 0.03`` both give ``{"segment_a.mass": 0.03}``.
    """
    path = Path(path)
    flat: dict[str, float] = {}

    def walk(node: dict, prefix: str) -> None:
        for key, value in node.items():
            dotted = f"{prefix}{key}"
            if isinstance(value, dict):
                walk(value, f"{dotted}.")
            else:
                flat[dotted] = value

    walk(_read(path), "")
    return flat


def write_overridden(overrides: dict[str, object], destination: Path | str,
                     config_dir: Path | str = CONFIG_DIR, **files: Path | str) -> Path:
    """Write the parameter files of ``config_dir`` (or ``files``) with ``overrides`` applied
    into the folder ``destination`` (read_config, parameters_from, write_config) and return it.
    Raises ParameterFileError naming the key or, after the overrides, the file and key;
    nothing is written then."""
    config = read_config(config_dir, overrides, **files)
    parameters_from(config)
    return write_config(config, destination)
