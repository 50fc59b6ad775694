"""The meshcat viewer of the arm (``Viewer``) and its server on 127.0.0.1 (``server``)."""

from phantom_pin.viewer.viewer import CAMERA_POSITION, FORCE_SCALE, Viewer

__all__ = ["Viewer", "CAMERA_POSITION", "FORCE_SCALE"]
