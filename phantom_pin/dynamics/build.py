"""The one builder of the PHANToM's Pinocchio models, as Pinocchio's own
``shortcuts.buildModelsFromUrdf`` is the one behind ``RobotWrapper.BuildFromURDF``.

``build_model`` turns a URDF text into a pinocchio.Model with the configuration's gravity: the
Coupling's two models, load()'s, and through them every model of phantom_pin.dynamics.pinocchio_models
(a Phantom's, which the ROS 2 node reuses) come from it; the SRDF's rotors are applied by
``load_rotor_parameters`` where ``has_rotors`` says so.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np
import pinocchio as pin

from phantom_pin.config import Config


def gravity_of(config: Config) -> pin.Motion:
    """Pinocchio's gravity of a configuration: (0, 0, -g) m/s^2 in base_link (a URDF cannot
    carry it; Pinocchio's default, 9.81, is the report's)."""
    return pin.Motion(np.array([0.0, 0.0, -config.gravity]), np.zeros(3))


def load_rotor_parameters(model: pin.Model, srdf_xml: str) -> None:
    """Set ``model.armature`` from an SRDF text's rotor_params (rotor inertia x ratio^2,
    kg m^2), as pinocchio.loadRotorParameters, which reads only files."""
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "rotors.srdf"
        path.write_text(srdf_xml, encoding="utf-8")
        pin.loadRotorParameters(model, str(path), False)


def has_rotors(config: Config | None) -> bool:
    """Whether the SRDF's rotor_params apply: a model without public motor data has none
    (Actuation.rotor: armature 0); a URDF file of one's own (no configuration) has them."""
    return config is None or config.actuation.motor is not None


def rooted_at(source: pin.Model, world_to_s: pin.SE3) -> pin.Model:
    """A copy of ``source`` expressed in frame s: every placement on the world, joints' and
    frames', premultiplied by ``world_to_s`` (gravity rotated alike)."""
    model = source.copy()
    for jid in range(1, model.njoints):
        if model.parents[jid] == 0:
            model.jointPlacements[jid] = world_to_s * model.jointPlacements[jid]
    for frame in model.frames:
        if frame.parentJoint == 0:
            frame.placement = world_to_s * frame.placement
    model.gravity = world_to_s.act(model.gravity)
    return model


def rooted_at_frame(model: pin.Model, frame: str) -> pin.Model:
    """``model`` rooted at its fixed frame ``frame`` (rooted_at, the frame's placement at the
    neutral configuration)."""
    data = model.createData()
    pin.framesForwardKinematics(model, data, pin.neutral(model))
    return rooted_at(model, data.oMf[model.getFrameId(frame)].inverse())


def build_model(urdf_xml: str, config: Config | None = None, *, mimic: bool = True,
                root_joint: pin.JointModel | None = None) -> pin.Model:
    """The pinocchio.Model of a URDF text: the mimic model (``mimic``) or the tree; with
    ``config``, its gravity (gravity_of; without, Pinocchio's). Pinocchio's errors pass through."""
    args = (urdf_xml,) if root_joint is None else (urdf_xml, root_joint)
    model = pin.buildModelFromXML(*args, mimic=mimic)
    if config is not None:
        model.gravity = gravity_of(config)
    return model
