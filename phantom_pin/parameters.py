"""The report's physical parameters, read from the description's config/*.yaml files."""

from __future__ import annotations

import dataclasses
import math
import os
import re
from pathlib import Path

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


def load_parameters(config_dir: Path | str = CONFIG_DIR, **overrides: Path | str) -> Parameters:
    """Read and check the parameter files; raise ParameterFileError naming file and key."""
    paths = parameter_paths(config_dir, **overrides)
    kin_path, phys_path = paths["kinematics_file"], paths["physical_parameters_file"]
    act_path, lim_path = paths["actuation_file"], paths["joint_limits_file"]
    kin, phys, act, lim = (_read(p) for p in (kin_path, phys_path, act_path, lim_path))

    def inertia(segment: str, axis: str) -> float:
        return _number(phys, phys_path, segment, "inertia", axis, positive=True)

    joints = ("joint1", "joint2", "joint3")
    lower = tuple(_number(lim, lim_path, j, "lower") for j in joints)
    upper = tuple(_number(lim, lim_path, j, "upper") for j in joints)
    for joint, lo, hi in zip(joints, lower, upper):
        for side, value in (("lower", lo), ("upper", hi)):
            if abs(value) > JOINT_LIMIT_BOUND:
                raise ParameterFileError(f"{lim_path}: {joint}.{side} must be within one turn "
                                         f"(|limit| <= 2 pi rad), got {value!r}")
        if lo >= hi:
            raise ParameterFileError(f"{lim_path}: {joint}.lower must be below {joint}.upper")
    return Parameters(
        l1=_number(kin, kin_path, "l1", positive=True),
        l2=_number(kin, kin_path, "l2", positive=True),
        l3=_number(kin, kin_path, "l3", positive=True),
        l5=_number(phys, phys_path, "segment_be", "com"),
        l6=_number(phys, phys_path, "segment_df", "com"),
        g=_number(phys, phys_path, "gravity", positive=True),
        ma=_number(phys, phys_path, "segment_a", "mass", positive=True),
        Iaxx=inertia("segment_a", "xx"), Iayy=inertia("segment_a", "yy"),
        Iazz=inertia("segment_a", "zz"),
        mc=_number(phys, phys_path, "segment_c", "mass", positive=True),
        Icxx=inertia("segment_c", "xx"), Icyy=inertia("segment_c", "yy"),
        Iczz=inertia("segment_c", "zz"),
        mbe=_number(phys, phys_path, "segment_be", "mass", positive=True),
        Ibexx=inertia("segment_be", "xx"), Ibeyy=inertia("segment_be", "yy"),
        Ibezz=inertia("segment_be", "zz"),
        mdf=_number(phys, phys_path, "segment_df", "mass", positive=True),
        Idfxx=inertia("segment_df", "xx"), Idfyy=inertia("segment_df", "yy"),
        Idfzz=inertia("segment_df", "zz"),
        Ibaseyy=_number(phys, phys_path, "segment_g", "inertia_yy", positive=True),
        rotor_inertia=_number(act, act_path, "motor", "rotor_inertia", positive=True),
        ratios=tuple(_number(act, act_path, "transmission_ratio", j, positive=True)
                     for j in joints),
        lower=lower,
        upper=upper,
        coupled=(_number(lim, lim_path, "stops", "theta2_minus_theta3_max"),
                 _number(lim, lim_path, "stops", "theta3_minus_theta2_max")),
    )


def random_states(params: Parameters, n: int,
                  seed: int | np.random.Generator) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``n`` seeded states (theta, dtheta, ddtheta), each (n, 3): theta uniform inside the
    joint limits (rad): the box and the coupled stops (``params.coupled``); rates and
    accelerations normal with standard deviations 2 rad/s and 20 rad/s^2. ``seed`` may be
    a Generator, to draw a long sequence in chunks."""
    rng = np.random.default_rng(seed)
    forward, backward = params.coupled
    theta = np.empty((0, 3))
    while len(theta) < n:  # rejection: about half of the box is inside the coupled stops
        draw = rng.uniform(params.lower, params.upper, (2 * n + 16, 3))
        keep = (draw[:, 1] - draw[:, 2] <= forward) & (draw[:, 2] - draw[:, 1] <= backward)
        theta = np.concatenate([theta, draw[keep]])
    return theta[:n], rng.normal(0, 2, (n, 3)), rng.normal(0, 20, (n, 3))


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
    """Copy the five parameter files (``config_dir``'s, or ``files`` by xacro arg name as
    in parameter_paths) into the folder ``destination`` with ``overrides`` applied, check
    them with load_parameters, and return the folder. The copies hold plain YAML numbers
    that any YAML 1.1 reader (xacro's) reads as numbers, whatever form the originals use.

    Keys are dotted paths into the files ("l1", "segment_a.mass", "joint2.upper"),
    optionally qualified by the file's stem ("actuation.motor.rotor_inertia"); an
    unqualified key must exist in exactly one file. Each must name a number, and each
    value must be a finite number in the units of that file (SI, radians). Comments
    are not copied.
    Raises ParameterFileError naming the key.
    """
    destination = Path(destination)
    paths = parameter_paths(config_dir, **files)
    documents = {name: _read(paths[arg]) for arg, name in PARAMETER_FILES.items()}
    stems = {Path(name).stem: name for name in documents}
    for key, value in overrides.items():
        parts = str(key).split(".")
        if parts[0] in stems and len(parts) > 1:  # qualified: "actuation.motor.rotor_inertia"
            holders, parts = [stems[parts[0]]], parts[1:]
        else:
            holders = [name for name, data in documents.items() if parts[0] in data]
        if not holders:
            raise ParameterFileError(f"{key}: no parameter file has the key {parts[0]!r}")
        if len(holders) > 1:
            raise ParameterFileError(f"{key}: {' and '.join(holders)} both have {parts[0]!r}; "
                                     f"qualify it, e.g. {Path(holders[0]).stem}.{key}")
        if parts[0] not in documents[holders[0]]:
            raise ParameterFileError(f"{key}: {holders[0]} has no key {parts[0]!r}")
        node: object = documents[holders[0]]
        for part in parts[:-1]:
            node = node.get(part) if isinstance(node, dict) else None
        current = node.get(parts[-1]) if isinstance(node, dict) else None
        if not _is_number(current):
            raise ParameterFileError(f"{key}: not a number in {holders[0]}, cannot override it")
        if not _is_number(value) or not math.isfinite(value):
            raise ParameterFileError(f"{key}: expected a finite number, got {value!r}")
        node[parts[-1]] = float(value)
    for name, data in documents.items():
        with open(destination / name, "w", encoding="utf-8") as stream:
            yaml.safe_dump(data, stream, sort_keys=False)
    try:
        load_parameters(destination)
    except ParameterFileError as error:  # name the file, not the temporary folder
        raise ParameterFileError(f"after the overrides, {str(error).replace(f'{destination}{os.sep}', '')}") from None
    return destination
