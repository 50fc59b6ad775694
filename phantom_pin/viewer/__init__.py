"""Where users look: the meshcat viewer of the arm (``Viewer``, in ``viewer``) and its server on
127.0.0.1 (``server``), and the self-contained HTML pages of a run's figures (``plots``).

``Viewer`` (and ``CAMERA_POSITION``, ``FORCE_SCALE``) are imported on first use: meshcat and
its dependencies load only for the viewer, not for a command that writes a page."""

from __future__ import annotations

import importlib
from typing import Any

__all__ = ["Viewer", "CAMERA_POSITION", "FORCE_SCALE"]


def __getattr__(name: str) -> Any:
    """The viewer's names, from phantom_pin.viewer.viewer when first asked for."""
    if name in __all__:
        return getattr(importlib.import_module("phantom_pin.viewer.viewer"), name)
    raise AttributeError(f"module 'phantom_pin.viewer' has no attribute {name!r}")
