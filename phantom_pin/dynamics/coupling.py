"""Adapter from a URDF's independent joints to its mimic-free tree model, read from <mimic> tags.

A URDF with mimic joints loads in Pinocchio two ways: ``mimic=True`` gives the
*reduced* model (one coordinate per independent joint), ``mimic=False`` the *tree*
model (one coordinate per joint). With v_tree = G v_reduced for a constant matrix G,
every quantity of the reduced system follows exactly from the tree model:
M = G^T M_tree G, C = G^T C_tree G, tau = G^T tau_tree, J = J_tree G. This covers the
algorithms that Pinocchio 4.1 refuses, or gets wrong, on mimic models (DEVELOPERS.md).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from phantom_pin.config import Config
from phantom_pin.description.mimic import Mimic, read_mimic_tags
from phantom_pin.dynamics.build import build_model
from phantom_pin.exceptions import ParameterFileError

#: Largest tree model (velocity dimension) whose projections use the Kronecker product.
_KRON_MAX_NV = 16


class Coupling:
    """The constant coupling between a reduced (mimic) model and its tree model.

    Attributes: ``tree`` and ``reduced`` (pinocchio.Model, phantom_pin.dynamics.build's; with
    ``config``, its gravity), ``matrix`` (G, shape
    (tree.nv, reduced.nv)) and ``mimics`` (the URDF's tags). Tangent vectors and
    matrices are mapped by G; configurations by ``configuration``.
    """

    def __init__(self, urdf_xml: str, root_joint: pin.JointModel | None = None, config: Config | None = None) -> None:
        self.tree = build_model(urdf_xml, config, mimic=False, root_joint=root_joint)
        self.reduced = build_model(urdf_xml, config, mimic=True, root_joint=root_joint)
        self.mimics = read_mimic_tags(urdf_xml)
        self.matrix = np.zeros((self.tree.nv, self.reduced.nv))
        # (tree idx_q, tree nq, reduced idx_q, multiplier, offset) per mimic joint
        self._mimic_slots: list[tuple[int, int, int, int, float, float]] = []
        self._copy_slots: list[tuple[int, int, int]] = []   # (tree idx_q, reduced idx_q, nq)
        for jid in range(1, self.tree.njoints):
            name, joint = self.tree.names[jid], self.tree.joints[jid]
            if name in self.mimics:
                self._add_mimic(joint, self.mimics[name])
            else:
                source = self.reduced.joints[self.reduced.getJointId(name)]
                self.matrix[joint.idx_v:joint.idx_v + joint.nv,
                            source.idx_v:source.idx_v + joint.nv] = np.eye(joint.nv)
                self._copy_slots.append((joint.idx_q, source.idx_q, joint.nq))
        self._transpose = np.ascontiguousarray(self.matrix.T)
        # G^T A G = reshape(A.ravel() . (G kron G)): one product instead of two, for small
        # models (the Kronecker product has (tree.nv reduced.nv)^2 entries)
        self._kron = np.kron(self.matrix, self.matrix) if self.tree.nv <= _KRON_MAX_NV else None
        # with only 1-coordinate joints, the configuration map is affine: q_tree = A q + b
        self._affine: tuple[np.ndarray, np.ndarray | None] | None = None
        if self.tree.nq == self.tree.nv and self.reduced.nq == self.reduced.nv:
            offset = np.zeros(self.tree.nq)
            for tree_q, _, _, _, _, angle in self._mimic_slots:
                offset[tree_q] = angle
            self._affine = self._transpose.copy(), (offset if offset.any() else None)

    def _add_mimic(self, joint: pin.JointModel, tag: Mimic) -> None:
        if tag.primary in self.mimics:
            raise ParameterFileError(f"joint {tag.joint}: mimics {tag.primary}, itself a mimic")
        if not self.reduced.existJointName(tag.primary):
            raise ParameterFileError(f"joint {tag.joint}: mimics unknown joint {tag.primary}")
        primary = self.reduced.joints[self.reduced.getJointId(tag.primary)]
        if joint.nv != 1 or primary.nv != 1:
            raise ParameterFileError(f"joint {tag.joint}: only 1-DoF mimic joints are supported")
        self.matrix[joint.idx_v, primary.idx_v] = tag.multiplier
        self._mimic_slots.append((joint.idx_q, joint.nq, primary.idx_q, primary.nq,
                                  tag.multiplier, tag.offset))

    def configuration(self, q_reduced: np.ndarray) -> np.ndarray:
        """Tree configuration (tree.nq,) of a reduced configuration (reduced.nq,); a batch
        (N, reduced.nq) too when every joint has one coordinate (no continuous joints)."""
        if self._affine is not None:
            transposed, offset = self._affine
            q = np.asarray(q_reduced).dot(transposed)
            return q if offset is None else q + offset
        q = np.empty(self.tree.nq)
        for tree_q, reduced_q, nq in self._copy_slots:
            q[tree_q:tree_q + nq] = q_reduced[reduced_q:reduced_q + nq]
        for tree_q, nq, primary_q, primary_nq, multiplier, shift in self._mimic_slots:
            if primary_nq == 1:
                angle = q_reduced[primary_q]
            else:  # continuous joint stored as (cos, sin)
                angle = np.arctan2(q_reduced[primary_q + 1], q_reduced[primary_q])
            angle = multiplier * angle + shift
            q[tree_q:tree_q + nq] = angle if nq == 1 else (np.cos(angle), np.sin(angle))
        return q

    def tangent(self, v_reduced: np.ndarray) -> np.ndarray:
        """Tree velocity or acceleration (tree.nv,) of a reduced one: G v; (N, tree.nv) of (N, reduced.nv)."""
        return np.asarray(v_reduced).dot(self._transpose)

    def project(self, tree_matrix: np.ndarray) -> np.ndarray:
        """G^T A G for a (..., tree.nv, tree.nv) matrix A (mass, Coriolis, derivatives)."""
        if self._kron is None:
            return self._transpose @ tree_matrix @ self.matrix
        # one 2-D product for any leading axes: BLAS, and the same rounding for a matrix
        # alone as inside a batch
        shape = tree_matrix.shape
        flat = tree_matrix.reshape(-1, shape[-2] * shape[-1])
        size = self.matrix.shape[1]
        return flat.dot(self._kron).reshape(shape[:-2] + (size, size))

    def project_force(self, tree_torque: np.ndarray) -> np.ndarray:
        """G^T tau: generalized force on the reduced coordinates."""
        return self._transpose @ tree_torque

    def project_jacobian(self, tree_jacobian: np.ndarray) -> np.ndarray:
        """J G: a (k, tree.nv) Jacobian as a Jacobian of the reduced coordinates."""
        return tree_jacobian @ self.matrix
