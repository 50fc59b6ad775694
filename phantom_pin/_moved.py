"""The modules that moved, importable at their old paths for one release.

``MOVED`` maps each old module path to its new one. ``install()`` (phantom_pin/__init__.py calls
it) puts a finder first on ``sys.meta_path`` that answers an old path with a module handing on
the new module's names, after a DeprecationWarning that names the new path (CHANGELOG.md,
"Moved"). ``phantom_pin.X`` for a moved root module ``X`` is answered the same way by the
package's ``__getattr__``. Nothing here imports a phantom_pin module until an old path is asked
for: the import graph (tests/test_imports.py) sees no edge."""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.machinery
import sys
import types
import warnings

#: Old module path -> new module path (0.x: the device integrations and identification's stages, issue 51).
MOVED = {
    "phantom_pin.drivers": "phantom_pin.interfaces.conventions",
    "phantom_pin.profiles": "phantom_pin.interfaces.profiles",
    "phantom_pin.forces": "phantom_pin.interfaces.forces",
    "phantom_pin.ros2": "phantom_pin.interfaces.ros2.node",
    "phantom_pin.sim_driver": "phantom_pin.interfaces.ros2.simulated_driver",
    "phantom_pin.inertial": "phantom_pin.description.inertial",
    "phantom_pin.plots": "phantom_pin.viewer.plots",
    "phantom_pin.verification": "phantom_pin.dynamics.verification",
    "phantom_pin.dynamics.model": "phantom_pin.dynamics.phantom",
    # identification/ in its stages: data, structure, fitting, verdict (issue 51, item 4)
    "phantom_pin.identification.io": "phantom_pin.identification.data.io",
    "phantom_pin.identification.bags": "phantom_pin.identification.data.bags",
    "phantom_pin.identification.timing": "phantom_pin.identification.data.timing",
    "phantom_pin.identification.simulation": "phantom_pin.identification.data.simulation",
    "phantom_pin.identification.cache": "phantom_pin.identification.structure.cache",
    "phantom_pin.identification.regressor": "phantom_pin.identification.structure.regressor",
    "phantom_pin.identification.base": "phantom_pin.identification.structure.base",
    "phantom_pin.identification.parameterization": "phantom_pin.identification.structure.parameterization",
    "phantom_pin.identification.constants": "phantom_pin.identification.structure.constants",
    "phantom_pin.identification.physical": "phantom_pin.identification.structure.physical",
    "phantom_pin.identification.structures": "phantom_pin.identification.structure.structures",
    "phantom_pin.identification.prior": "phantom_pin.identification.structure.prior",
    "phantom_pin.identification.least_squares": "phantom_pin.identification.fitting.least_squares",
    "phantom_pin.identification.filtering": "phantom_pin.identification.fitting.filtering",
    "phantom_pin.identification.instruments": "phantom_pin.identification.fitting.instruments",
    "phantom_pin.identification.prediction": "phantom_pin.identification.fitting.prediction",
    "phantom_pin.identification.fit": "phantom_pin.identification.fitting.fit",
    "phantom_pin.identification.checks": "phantom_pin.identification.fitting.checks",
    "phantom_pin.identification.selection": "phantom_pin.identification.fitting.selection",
    "phantom_pin.identification.estimation": "phantom_pin.identification.fitting.estimation",
    "phantom_pin.identification.excitation": "phantom_pin.identification.fitting.excitation",
    "phantom_pin.identification.static": "phantom_pin.identification.fitting.static",
    "phantom_pin.identification.result": "phantom_pin.identification.verdict.result",
    "phantom_pin.identification.overlays": "phantom_pin.identification.verdict.overlays",
    "phantom_pin.identification.page": "phantom_pin.identification.verdict.page",
}


def message(old: str) -> str:
    """The DeprecationWarning's text for the old path ``old``."""
    return f"{old} moved to {MOVED[old]}; the old path works until the next release (CHANGELOG.md)"


class _Forward(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Answers each old path of MOVED with a module whose attributes are the new module's."""

    def find_spec(self, fullname, path=None, target=None):  # noqa: ANN001 - importlib's signature
        return importlib.machinery.ModuleSpec(fullname, self) if fullname in MOVED else None

    def create_module(self, spec):  # noqa: ANN001
        return None     # a plain module, filled by exec_module

    def exec_module(self, module: types.ModuleType) -> None:
        warnings.warn(message(module.__name__), DeprecationWarning, stacklevel=_importer_level())
        target = importlib.import_module(MOVED[module.__name__])
        module.__getattr__ = lambda name: getattr(target, name)     # type: ignore[method-assign]
        module.__dir__ = lambda: dir(target)                        # type: ignore[method-assign]
        module.__doc__ = f"Moved to {target.__name__}.\n\n{target.__doc__ or ''}"
        if hasattr(target, "__all__"):
            module.__dict__["__all__"] = list(target.__all__)


def _importer_level() -> int:
    """warnings.warn's stacklevel of the frame that asked for the import (past importlib's own
    frames and this file's), so that Python's default filters show it in a user's script."""
    frame: types.FrameType | None = sys._getframe(1)
    level = 1
    while frame is not None and (frame.f_code.co_filename.startswith("<frozen importlib")
                                 or frame.f_code.co_filename == __file__):
        frame, level = frame.f_back, level + 1
    return level


_FINDER = _Forward()


def install() -> None:
    """Put the finder first on sys.meta_path (once)."""
    if _FINDER not in sys.meta_path:
        sys.meta_path.insert(0, _FINDER)


def root_attribute(name: str) -> types.ModuleType:
    """``phantom_pin.NAME`` for a moved root module NAME (the package's ``__getattr__``)."""
    if f"phantom_pin.{name}" not in MOVED:
        raise AttributeError(f"module 'phantom_pin' has no attribute {name!r}")
    return importlib.import_module(f"phantom_pin.{name}")
