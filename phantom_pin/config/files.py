"""The parameter files of a configuration folder: YAML read once each, overrides applied.

This is the only module that opens a parameter file. Everything it returns is plain data
(mappings of mappings); phantom_pin.config.builders turns it into the typed Config (config.types).
"""

from __future__ import annotations

import copy
import math
import re
from pathlib import Path
from typing import cast

import yaml

from phantom_pin.config.types import JOINTS
from phantom_pin.exceptions import ParameterFileError

#: The parameter files of a configuration folder, by the xacro argument that names them.
FILES = {
    "kinematics_file": "kinematics.yaml",
    "physical_parameters_file": "physical_parameters.yaml",
    "actuation_file": "actuation.yaml",
    "joint_limits_file": "joint_limits.yaml",
    "visual_parameters_file": "visual_parameters.yaml",
    "mjcf_file": "mjcf.yaml",
    "gimbal_file": "gimbal.yaml",
}
#: The files a configuration may leave out (read as an empty mapping): a model without a
#: public stylus gimbal has no gimbal.yaml.
OPTIONAL = ("gimbal_file",)
#: The keys that hold a number per joint, by file: each is one number (the same on every joint)
#: or a mapping {joint1, joint2, joint3} of numbers (config.reader.Reader.per_joint), and an
#: override may set one joint of it (apply_overrides).
PER_JOINT = {"actuation_file": (("friction", "viscous"), ("friction", "coulomb"))}


class _Loader(getattr(yaml, "CSafeLoader", yaml.SafeLoader)):  # type: ignore[misc]
    """PyYAML's safe loader (libyaml's parser where PyYAML has it: the same documents, a tenth of
    the parsing time), which also reads 1e-6 and 1.0e6 as numbers, and refuses a key given
    twice in one mapping (PyYAML silently keeps the last; YAML 1.2 forbids it).

    PyYAML follows YAML 1.1, whose floats need a dot and a signed exponent: it reads
    ``1e-6`` and ``1.0e6`` as strings (``1.0e-6`` and ``1.0e+6`` as numbers). YAML 1.2
    reads all four as numbers, and so does this loader.
    """

    def construct_mapping(self, node: yaml.MappingNode, deep: bool = False) -> dict:
        seen: set[object] = set()
        for key_node, _ in node.value:
            key = self.construct_object(key_node, deep=deep)
            if key in seen:
                raise yaml.constructor.ConstructorError(None, None, f"the key {key!r} is given twice",
                                                        key_node.start_mark)
            if isinstance(key, (str, int, float)):
                seen.add(key)
        return super().construct_mapping(node, deep=deep)


_Loader.add_implicit_resolver(
    "tag:yaml.org,2002:float", re.compile(r"^[-+]?[0-9][0-9_]*(?:\.[0-9_]*)?[eE][-+]?[0-9]+$"),
    list("-+0123456789"))


def read_yaml(path: Path) -> dict:
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


def is_number(value: object) -> bool:
    """True for an int or float that is not a bool (YAML's true/false)."""
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def read_documents(folder: Path) -> dict[str, dict]:
    """Each parameter file of ``folder`` read once: its mapping by xacro argument name (an
    empty mapping for an OPTIONAL file the folder does not have); ParameterFileError naming the
    folder if it has none of them (not a configuration folder)."""
    if not any((folder / name).exists() for name in FILES.values()):
        raise ParameterFileError(f"{folder}: not a configuration folder (it has none of "
                                 f"{', '.join(FILES.values())}; see robots/phantom_description/config)")
    return {arg: {} if arg in OPTIONAL and not (folder / name).exists() else read_yaml(folder / name)
            for arg, name in FILES.items()}


def apply_overrides(documents: dict[str, dict], overrides: dict[str, object]) -> dict[str, dict]:
    """A copy of ``documents`` with ``overrides`` applied, in order.

    Override keys are dotted paths into the files ("l1", "segment_a.mass", "joint2.upper"),
    optionally qualified by the file's stem ("actuation.motor.rotor_inertia"); an
    unqualified key must exist in exactly one file. Each must name a number, and each
    value must be a finite number in the units of that file (SI, radians); an item of a
    list is named by its index ("links.forearm_link.com.2"). A per-joint key (PER_JOINT:
    actuation.yaml's friction.viscous and friction.coulomb) takes one joint's value
    ("actuation.friction.viscous.joint2"; a file's single number is first expanded to the
    same value on every joint), or without a joint sets every joint to the value, whether the
    file holds one number or a mapping. ParameterFileError naming the key otherwise.
    """
    documents = copy.deepcopy(documents)
    stems = {Path(name).stem: arg for arg, name in FILES.items()}
    for key, value in overrides.items():
        arg, parts = _holder(documents, stems, key)
        _override(documents[arg], arg, parts, key, value)
    return documents


def _holder(documents: dict[str, dict], stems: dict[str, str], key: object) -> tuple[str, list[str]]:
    """The file argument that holds the override ``key`` (by its stem if qualified, else the
    one file with its first part), and the key's parts within it."""
    parts = str(key).split(".")
    if parts[0] in stems and len(parts) > 1:  # qualified: "actuation.motor.rotor_inertia"
        holders, parts = [stems[parts[0]]], parts[1:]
    else:
        holders = [arg for arg, document in documents.items() if parts[0] in document]
    if not holders:
        raise ParameterFileError(f"{key}: no parameter file has the key {parts[0]!r}")
    if len(holders) > 1:
        names = [FILES[arg] for arg in holders]
        raise ParameterFileError(f"{key}: {' and '.join(names)} both have {parts[0]!r}; "
                                 f"qualify it, e.g. {Path(names[0]).stem}.{key}")
    return holders[0], parts


def _override(document: dict, arg: str, parts: list[str], key: object, value: object) -> None:
    """The number at ``parts`` in ``document`` (the file of ``arg``) set to ``value``, in place
    (apply_overrides' doc)."""
    name = FILES[arg]
    node: object = document
    per_joint = PER_JOINT.get(arg, ())
    if tuple(parts[:-1]) in per_joint:      # one joint of a per-joint key
        _expand(node, parts, key, name)
    for part in parts[:-1]:
        node = _child(node, part)
    if _child(node, parts[-1]) is None and parts[0] not in document:
        raise ParameterFileError(f"{key}: {name} has no key {parts[0]!r}")
    whole = tuple(parts) in per_joint and isinstance(_child(node, parts[-1]), dict)   # every joint at once
    if not is_number(_child(node, parts[-1])) and not whole:
        raise ParameterFileError(f"{key}: not a number in {name}, cannot override it")
    if not is_number(value) or not math.isfinite(cast(float, value)):
        raise ParameterFileError(f"{key}: expected a finite number, got {value!r}")
    if isinstance(node, list):
        node[int(parts[-1])] = float(cast(float, value))
    else:
        cast(dict, node)[parts[-1]] = float(cast(float, value))


def _expand(document: object, parts: list[str], key: object, name: str) -> None:
    """``parts`` (a per-joint key and a joint) checked, the key's number in ``document`` replaced
    by the same number on every joint (a mapping is left as it is)."""
    joint = parts[-1]
    if joint not in JOINTS:
        raise ParameterFileError(f"{key}: {'.'.join(parts[:-1])} is per joint: name {', '.join(JOINTS)} "
                                 f"after it, not {joint!r}")
    node = document
    for part in parts[:-2]:
        node = _child(node, part)
    held = _child(node, parts[-2])
    if is_number(held):
        cast(dict, node)[parts[-2]] = {j: held for j in JOINTS}
    elif not isinstance(held, dict):
        raise ParameterFileError(f"{key}: {name} has no number or mapping of joints at {'.'.join(parts[:-1])}")


def _child(node: object, part: str) -> object:
    if isinstance(node, dict):
        return node.get(part)
    if isinstance(node, list) and part.isdigit() and int(part) < len(node):
        return node[int(part)]
    return None


#: The key of an overrides file that names the model it was made for (identify's overlays):
#: read() refuses to apply it to another model.
MODEL_KEY = "model"


def read_overrides(path: Path | str) -> dict[str, float]:
    """Read a YAML file of parameter overrides into dotted keys.

    Nested mappings and dotted keys are equivalent: ``segment_a: {mass: 0.03}`` and
    ``segment_a.mass: 0.03`` both give ``{"segment_a.mass": 0.03}``; one number given both
    ways, or a key given twice, is refused (ParameterFileError naming the file).
    """
    flat: dict[str, float] = {}

    def walk(node: dict, prefix: str) -> None:
        for key, value in node.items():
            dotted = f"{prefix}{key}"
            if isinstance(value, dict):
                walk(value, f"{dotted}.")
            elif dotted in flat:
                raise ParameterFileError(f"{path}: {dotted} is given twice (nested and dotted)")
            else:
                flat[dotted] = value

    walk(read_yaml(Path(path)), "")
    return flat
