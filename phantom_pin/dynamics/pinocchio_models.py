"""Every Pinocchio model of a description, built once (phantom_pin.dynamics.build): the ones a
Phantom holds, and the ROS 2 node and the force renderer reuse through it."""

from __future__ import annotations

import dataclasses

import numpy as np
import pinocchio as pin

from phantom_pin.config.types import GIMBAL_JOINTS
from phantom_pin.description.build import Description
from phantom_pin.description.gimbal import locked
from phantom_pin.dynamics.build import has_rotors, load_rotor_parameters, rooted_at_frame
from phantom_pin.dynamics.coupling import Coupling


@dataclasses.dataclass(frozen=True)
class PinocchioModels:
    """Every model of a description: ``coupling`` (the arm's mimic model, ``coupling.reduced``,
    with the rotors' armature, and its tree; a gimbal locked at ``locked_at``), ``full`` (every
    joint of the URDF free: ``coupling`` itself without a gimbal), ``stylus`` (the six-joint mimic
    model rooted at frame s, with the arm's armature, or None without a gimbal) and ``order`` (the
    stylus model's q indices of (theta1..3, g1..3), or None)."""

    coupling: Coupling
    full: Coupling
    stylus: pin.Model | None
    order: np.ndarray | None


def pinocchio_models(description: Description) -> PinocchioModels:
    """The Pinocchio models of ``description``, gravity and rotors applied once."""
    config, prefix = description.config, description.prefix
    gimbal = config.gimbal
    coupling = Coupling(description.urdf if gimbal is None else locked(description.urdf, prefix, gimbal.locked_at),
                        config=config)
    if has_rotors(config):  # else no rotor_params, armature 0 (Actuation.rotor)
        load_rotor_parameters(coupling.reduced, description.srdf)
    if gimbal is None:
        return PinocchioModels(coupling, coupling, None, None)
    full = Coupling(description.urdf, config=config)
    stylus = rooted_at_frame(full.reduced, prefix + "report_s")
    names = (*(f"{prefix}joint{j}" for j in (1, 2, 3)), *(prefix + j for j in GIMBAL_JOINTS))
    order = np.array([stylus.joints[stylus.getJointId(n)].idx_q for n in names])
    armature = stylus.armature.copy()
    armature[order[:3]] = coupling.reduced.armature  # the rotors, as the arm's model has them
    stylus.armature = armature
    return PinocchioModels(coupling, full, stylus, order)
