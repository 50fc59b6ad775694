"""Reading a configuration: a model name or folder, its files read once each, the overrides
applied (their sources marked OVERRIDDEN), built into one typed Config."""

from __future__ import annotations

from pathlib import Path

from phantom_pin.config.builders import REPORT_SEGMENTS, SOURCES, build, in_full
from phantom_pin.config.files import MODEL_KEY, apply_overrides, read_documents
from phantom_pin.config.models import DEFAULT, resolve
from phantom_pin.config.types import Config
from phantom_pin.exceptions import ParameterFileError


def read(model: str | Path = DEFAULT, overrides: dict[str, object] | None = None) -> Config:
    """The Config of a model name (phantom_pin.models()) or a configuration folder, its
    files read once each, with ``overrides`` (dotted keys, files.apply_overrides) applied.
    An override ``model`` (files.MODEL_KEY, as identify's overlay writes it) must name this
    model. Raises ParameterFileError naming the file and the key (or ``model`` for overrides
    made for another model), InvalidInputError naming ``model`` for an unknown name or folder."""
    name, folder, _ = resolve(model)
    overrides = dict(overrides or {})
    made_for = overrides.pop(MODEL_KEY, None)
    if made_for is not None and made_for != name:
        raise ParameterFileError(f"{MODEL_KEY}: these overrides were made for the model {made_for!r} (an "
                                 f"identification's overlay, valid on its lengths and links only), not for "
                                 f"{name!r}; choose --model {made_for}")
    documents = read_documents(folder)
    in_links = {key: value for key, value in overrides.items() if section(key) == "links"}
    if in_links and "links" not in documents["physical_parameters_file"]:
        # a model in the report's form given links in full (identify's overlay): its five
        # bodies in full, as its files give them (builders.in_full), then every override on them
        mixed = sorted(key for key in overrides if section(key) in REPORT_SEGMENTS)
        if mixed:
            raise ParameterFileError(f"{mixed[0]}: the report's segments and links.* describe the same bodies "
                                     "two ways; give the links in full only")
        documents = in_full(documents, build(documents, name, folder, False))
    if overrides:
        documents = _sourced(documents, apply_overrides(documents, overrides))
    return build(documents, name, folder, bool(overrides))


#: The keys of a file whose numbers a section's source speaks for (default: the section's own;
#: None: the whole file).
_SPOKEN_FOR = {("actuation_file", "motor"): ("motor", "joint_torque_limit", "joint_velocity_limit"),
               ("gimbal_file", "gimbal"): None}


def _changed(before: object, after: object, prefix: str = "") -> list[str]:
    """The dotted paths at which ``after`` differs from ``before`` (a number expanded into a
    mapping of joints compared joint by joint)."""
    if isinstance(after, dict) and not isinstance(before, (dict, type(None))):
        before = dict.fromkeys(after, before)
    if isinstance(before, dict) and isinstance(after, dict):
        return [path for key in dict.fromkeys([*before, *after])
                for path in _changed(before.get(key), after.get(key), f"{prefix}{key}.")]
    return [] if before == after else [prefix.rstrip(".")]


def _sourced(before: dict[str, dict], after: dict[str, dict]) -> dict[str, dict]:
    """``after`` (the documents with the overrides applied) with the source of each section
    whose numbers the overrides changed saying so: its numbers are no longer all its source's."""
    for arg, sections in SOURCES.items():
        for name in sections:
            spoken = _SPOKEN_FOR.get((arg, name), (name,))
            keys = [k for k in after[arg] if k != "sources"] if spoken is None else list(spoken)
            changed = _changed({k: before[arg].get(k) for k in keys}, {k: after[arg].get(k) for k in keys})
            if changed and isinstance(after[arg].get("sources"), dict) and name in after[arg]["sources"]:
                after[arg]["sources"][name] = (f"OVERRIDDEN here: {', '.join(changed)} (not from the source); "
                                               f"the rest: {after[arg]['sources'][name]}")
    return after


def section(key: object) -> str:
    """The top-level section of physical_parameters.yaml an override key names ("links" for
    "links.forearm_link.mass" and "physical_parameters.links.forearm_link.mass")."""
    parts = str(key).split(".")
    return parts[1] if parts[0] == "physical_parameters" and len(parts) > 1 else parts[0]
