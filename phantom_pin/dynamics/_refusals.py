"""The messages of the constructors' refusals: what was given, and the call that makes the
object of it (Phantom, Device, load and check refuse the other kinds of input by name)."""

from __future__ import annotations

from pathlib import Path

from phantom_pin.config import MODELS
from phantom_pin.description.build import Description
from phantom_pin.exceptions import InvalidInputError


def shown(value: object) -> str:
    """``value`` for a refusal's message: its repr up to 60 characters (a Description by its
    type and configuration's name, not its texts)."""
    if isinstance(value, Description):
        return f"a Description (of {value.config.name})"
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def constructor(cls: str, given: object) -> str:
    """The call that makes a ``cls`` ("Phantom" or "Device") of what its plain call was ``given``
    and refused, for the refusal's message: a model name's from_model, a folder's
    Phantom.from_folder, a Description's Phantom(description)."""
    wrap = (lambda call: call) if cls == "Phantom" else (lambda call: f"Device({call})")
    if isinstance(given, str) and given in MODELS:
        return f"a named model is {cls}.from_model({given!r})"
    if isinstance(given, Path) or (isinstance(given, str) and Path(given).is_dir()):
        return f"a configuration folder is {wrap('Phantom.from_folder(path)')}"
    if isinstance(given, Description):
        return f"a Description is {wrap('Phantom(description)')}"
    folder = wrap("Phantom.from_folder(path)")
    return f"a model name ({', '.join(MODELS)}) is {cls}.from_model(model), a folder {folder}"


def refusal(cls: str, expected: str, given: object, argument: str) -> InvalidInputError:
    """The error of ``cls``'s plain call (or of a function taking one) given what it does not
    take: ``expected`` (e.g. "a phantom_pin.Phantom or None"), what was given, and the call
    that makes the object of it (constructor), naming ``argument``."""
    return InvalidInputError(f"expected {expected}, got {shown(given)}; {constructor(cls, given)}", argument=argument)
