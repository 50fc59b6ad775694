"""A Fit (estimation.estimate) as a --params overlay: the keys of the identified bodies, each
joint's friction, and what the fit is only valid with (its model and lengths; the stylus posture
it was held at: ``stylus_keys``); ``yaml_text`` and ``write_yaml``, the one writer of an overlay's text and file (the
fit's comments: result.py; gravity from rest: ``gravity_overlay``; docs/identification.md, step 9)."""

from __future__ import annotations

import dataclasses
from pathlib import Path

from phantom_pin._validation import output_path
from phantom_pin.config import MODEL_KEY, MODELS, REPORT_SEGMENTS, Config, section
from phantom_pin.description.build import describe
from phantom_pin.dynamics.phantom import Phantom
from phantom_pin.exceptions import InvalidInputError, ParameterFileError, PhantomPinError
from phantom_pin.identification.fitting.fit import Fit
from phantom_pin.identification.fitting.static import Gravity
from phantom_pin.identification.structure.structures import General


def overlay(fit: Fit, given: dict | None = None, config: Config | None = None) -> tuple[dict[str, object], list[str]]:
    """The --params keys of an identification (estimation.Fit) on a model with the overrides
    ``given`` (those of the bodies it identified dropped: the segments and links), and the
    comment lines that explain its friction. Friction is written per joint, always
    (``actuation.friction.viscous.joint1`` .. ``actuation.friction.coulomb.joint3``, N m s/rad
    and N m): the physical projection's values (fit.x, never negative; the friction keys of
    ``given`` are dropped); the comments list each joint's estimate +- its standard deviation.

    With the ``config`` identified on, the keys carry what the fit is only valid with: its
    lengths l1, l2, l3 (m) and, for a named model, ``model`` (its name), which
    phantom_pin.config.read checks against the model the keys are applied to; and they are
    checked to give a physical model of that configuration (describe() and its physical check
    of every link): ParameterFileError otherwise, before anything is written."""
    if not isinstance(fit, Fit):
        raise InvalidInputError(f"expected a phantom_pin.identification.Fit (estimate), got {fit!r}", argument="fit")
    keys = identified_keys(fit.overrides, given, config, friction_keys(fit))
    notes = []
    values, sigma = fit.friction
    for kind, part in (("viscous", slice(0, 3)), ("coulomb", slice(3, 6))):
        listed = ", ".join(f"joint{j} {v:.4g} +- {s:.2g}" for j, v, s in zip((1, 2, 3), values[part], sigma[part]))
        notes.append(f"friction.{kind} estimated per joint: {listed}; written per joint, the physical values "
                     "(0 or more)")
    return keys, notes


def identified_keys(bodies: dict[str, float], given: dict | None, config: Config | None,
                    friction: dict[str, float] | None) -> dict[str, object]:
    """The overlay's keys: what the fit is valid with (``config``'s name and lengths), the
    overrides ``given`` except the identified ``bodies``' and (where ``friction`` is identified)
    friction's, then ``bodies`` and ``friction``; checked to give a physical model of ``config``
    (describe() and its check of every link): ParameterFileError otherwise."""
    if given is not None and not isinstance(given, dict):
        raise InvalidInputError(f"expected a dict of --params keys or None, got {given!r}", argument="given")
    keys: dict[str, object] = {}
    if config is not None:
        if config.name in MODELS:
            keys[MODEL_KEY] = config.name
        keys.update(dataclasses.asdict(config.kinematics))
    keys.update({key: value for key, value in (given or {}).items()
                 if section(key) not in REPORT_SEGMENTS + ("links",) and not (friction and _friction_key(key))})
    keys.update(bodies)
    keys.update(friction or {})
    if config is not None:  # the overlay must give a physical URDF (description.physical.check_urdf)
        try:
            describe(config.folder, overrides=keys)
        except PhantomPinError as error:
            raise ParameterFileError(f"identified parameters not physically valid: {error}") from None
    return keys


#: The overlay's friction keys in fit.x[-6:]'s order: viscous1..3 (N m s/rad), coulomb1..3 (N m).
FRICTION_KEYS = tuple(f"actuation.friction.{kind}.joint{j}" for kind in ("viscous", "coulomb") for j in (1, 2, 3))


def friction_keys(fit: Fit) -> dict[str, float]:
    """Each joint's friction of ``fit`` as --params keys (FRICTION_KEYS): the physical
    projection's values, fit.x[-6:] (never negative)."""
    return {key: float(value) for key, value in zip(FRICTION_KEYS, fit.x[-6:], strict=True)}


def _friction_key(key: object) -> bool:
    """Whether an override key names actuation.yaml's friction (any of its forms)."""
    parts = str(key).split(".")
    return parts[1 if parts[0] == "actuation" else 0:][:1] == ["friction"]


def stylus_keys(config: Config) -> dict[str, float]:
    """The overrides of ``config``'s stylus posture, ``gimbal.locked_at.0..2`` (rad): what an overlay
    identified on a model whose stylus was held (description.build.held, at a recording's gimbal
    angles) carries in its ``given``, so that it is applied with the load it was fitted with; none
    for a model without a stylus gimbal."""
    gimbal = config.gimbal
    return {} if gimbal is None else {f"gimbal.locked_at.{k}": float(a) for k, a in enumerate(gimbal.locked_at)}


def gravity_overlay(gravity: Gravity, phantom: Phantom, given: dict | None, source: str, lines: list[str]) -> str:
    """The overlay of gravity from rest (static.estimate_gravity on ``phantom``, made with the
    overrides ``given``): the rigid body's keys (friction as given), the comment ``lines`` after
    one naming the ``source`` (the log's name)."""
    keys = identified_keys(General(phantom).overrides(gravity.x), given, phantom.config, None)
    return yaml_text([f"Identified by phantom-pin identify --static from {source}: a --params overlay of the rigid "
                      "body (gravity from rest postures; friction as given). SI units.", *lines], keys)


def yaml_text(comments: list[str], keys: dict[str, object]) -> str:
    """An overlay's text: the ``comments`` (one ``# `` line each), then the ``keys`` as YAML."""
    lines = [f"# {line}" for line in comments] + [f"{key}: {value!r}" for key, value in keys.items()]
    return "\n".join(lines) + "\n"


def write_yaml(path: Path | str, text: str, force: bool = False) -> None:
    """The overlay ``text`` (yaml_text) into the file ``path``; an existing file only with ``force``
    (InvalidInputError naming ``path`` otherwise)."""
    path = output_path(path, force, "path")
    path.write_text(text, encoding="utf-8")
