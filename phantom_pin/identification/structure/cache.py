"""What the identification computes once per Description (its affine maps, the report
constants' matrix, the general structure's base): kept beside the Description, keyed by it
(by identity, as a frozen Description compares), and dropped with it. The Description itself
stays immutable and knows nothing of it."""

from __future__ import annotations

import weakref
from collections.abc import Callable, Hashable
from typing import Any

from phantom_pin.description.build import Description

_ENTRIES: weakref.WeakKeyDictionary[Description, dict[Hashable, Any]] = weakref.WeakKeyDictionary()


def cached(description: Description, key: Hashable, compute: Callable[[], Any]) -> Any:
    """``compute()`` for ``description`` and ``key``, computed on the first call only."""
    entries = _ENTRIES.setdefault(description, {})
    if key not in entries:
        entries[key] = compute()
    return entries[key]
