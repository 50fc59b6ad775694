"""The joint-torque regressor in the report's coordinates: tau = Y(theta, dtheta, ddtheta) pi.

pi stacks, in this order (``Regressor.names``):

- the 10 standard inertial parameters of each moving body of the mimic-free tree model,
  in Pinocchio's order [m, m c_x, m c_y, m c_z, I_xx, I_xy, I_yy, I_xz, I_yz, I_zz]
  (kg, kg m, kg m^2), c the centre of mass and I the inertia *about the joint frame's
  origin*, both in the body's joint frame (the URDF link frame);
- the reflected rotor inertia of each motor, J r_i^2 (kg m^2), acting on ddtheta_i;
- per joint, a viscous coefficient (N m s/rad) on dtheta_i and a Coulomb torque (N m) on
  sign(dtheta_i): actuation.yaml's friction law in motion (config.Friction).

Pinocchio refuses computeJointTorqueRegressor on mimic models, so it runs on the tree
model at the tree state (q_tree from the mimic tags, v_tree = G dtheta, a_tree = G ddtheta)
and is projected: Y = G^T Y_tree. Gravity is the model's (base_link -z).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from phantom_pin._validation import as_states, same_batch
from phantom_pin.dynamics.phantom import Phantom
from phantom_pin.exceptions import InvalidInputError

#: Pinocchio's order of the standard parameters of one body (pin.Inertia.toDynamicParameters).
INERTIAL_NAMES = ("m", "mx", "my", "mz", "Ixx", "Ixy", "Iyy", "Ixz", "Iyz", "Izz")


def body_names(tree: pin.Model) -> list[str]:
    """The URDF link carried by each moving joint of ``tree`` (joint 1 .. njoints-1)."""
    body: dict[int, str] = {}
    for frame in tree.frames:
        if frame.type == pin.FrameType.BODY:
            body.setdefault(frame.parentJoint, frame.name)
    return [body[i] for i in range(1, tree.njoints)]


class Regressor:
    """Y(theta, dtheta, ddtheta) of a Phantom: (..., 3, n_parameters), see the module doc.
    The friction columns follow the Phantom's own friction law in motion (config.Friction)."""

    def __init__(self, phantom: Phantom) -> None:
        if not isinstance(phantom, Phantom):
            raise InvalidInputError(f"expected a phantom_pin.Phantom, got {phantom!r}", argument="phantom")
        self.phantom = phantom
        self.coupling = self.phantom.coupling
        self.tree = self.coupling.tree
        self._data = self.tree.createData()
        #: the Coulomb column: the friction law with unit Coulomb and no viscous term
        self._coulomb = phantom.config.actuation.friction.unit_coulomb().torque
        self.bodies = body_names(self.tree)
        self.n_inertial = 10 * len(self.bodies)
        self.names = ([f"{b}.{p}" for b in self.bodies for p in INERTIAL_NAMES]
                      + [f"rotor{j}" for j in (1, 2, 3)] + [f"viscous{j}" for j in (1, 2, 3)]
                      + [f"coulomb{j}" for j in (1, 2, 3)])
        #: what each tree body carries beyond its URDF link, (n_inertial,): a stylus gimbal that
        #: the Phantom's model holds locked on the forearm (Phantom's doc); zero elsewhere. A known
        #: load: the structures add it to the parameters they identify, and the overlay leaves it out.
        prefix, links = phantom.description.prefix, phantom.config.links
        self.carried = np.concatenate([
            self.tree.inertias[k + 1].toDynamicParameters() - links[body[len(prefix):]].dynamic_parameters()
            if phantom.config.gimbal is not None and body[len(prefix):] == "forearm_link" else np.zeros(10)
            for k, body in enumerate(self.bodies)])
        #: column slices: inertial (tree bodies), rotors, friction
        self.inertial = slice(0, self.n_inertial)
        self.rotors = slice(self.n_inertial, self.n_inertial + 3)
        self.friction = slice(self.n_inertial + 3, self.n_inertial + 9)

    @property
    def size(self) -> int:
        return len(self.names)

    def parameters(self, viscous: object = 0.0, coulomb: object = 0.0) -> np.ndarray:
        """pi of the loaded model: its tree inertias, its armature, and the given friction
        (scalars or one value per joint, N m s/rad and N m)."""
        inertial = [self.tree.inertias[i].toDynamicParameters() for i in range(1, self.tree.njoints)]
        return np.concatenate(inertial + [np.asarray(self.phantom.model.armature, float),
                                          np.broadcast_to(np.asarray(viscous, float), 3),
                                          np.broadcast_to(np.asarray(coulomb, float), 3)])

    def __call__(self, theta: object, dtheta: object, ddtheta: object) -> np.ndarray:
        """Y at one state (3, P) or a batch (N, 3, P); rad, rad/s, rad/s^2 -> N m per unit."""
        q, _ = as_states(theta, "theta")
        v, _ = as_states(dtheta, "dtheta")
        a, _ = as_states(ddtheta, "ddtheta")
        same_batch(("theta", "dtheta", "ddtheta"), q, v, a)
        shape = q.shape[:-1]
        q, v, a = (x.reshape(-1, 3) for x in (q, v, a))
        c = self.coupling
        # Pinocchio once per state on the tree; the projection G^T Y_tree and the diagonal
        # rotor and friction columns for the whole batch
        tree_q, tree_v, tree_a = c.configuration(q), c.tangent(v), c.tangent(a)
        tree_y = np.empty((len(q), self.tree.nv, self.n_inertial))
        regressor, tree, data = pin.computeJointTorqueRegressor, self.tree, self._data
        for i in range(len(q)):
            tree_y[i] = regressor(tree, data, tree_q[i], tree_v[i], tree_a[i])
        out = np.zeros((len(q), 3, self.size))
        out[..., self.inertial] = np.einsum("tj,ntp->njp", c.matrix, tree_y)
        rows = np.arange(3)
        out[:, rows, self.rotors.start + rows] = a
        out[:, rows, self.friction.start + rows] = v
        out[:, rows, self.friction.start + 3 + rows] = self._coulomb(v)
        return out.reshape(shape + (3, self.size))

    def stacked(self, theta: object, dtheta: object, ddtheta: object) -> np.ndarray:
        """Y of a batch stacked into (3N, P): rows tau1, tau2, tau3 of state 0, then state 1..."""
        return self(theta, dtheta, ddtheta).reshape(-1, self.size)
