"""dynamics.pinocchio_models: the models of a description against models built here by Pinocchio
alone from the same URDF text: the Premium 1.5's one mimic model with its rotors (armature r^2 J),
the Touch's arm with its gimbal locked and its six-joint stylus model, whose gravity torques on
the arm at the locked gimbal angles equal the locked model's (a frame-free quantity, 1e-12 N m),
its order the q indices of theta1..3, g1..3 and its arm armature the arm model's."""

import numpy as np
import pinocchio as pin

from phantom_pin import describe
from phantom_pin.config.types import GIMBAL_JOINTS
from phantom_pin.dynamics.pinocchio_models import pinocchio_models


def test_a_model_without_a_gimbal_is_one_mimic_model_with_its_rotors():
    description = describe()
    models = pinocchio_models(description)
    assert models.full is models.coupling and models.stylus is None and models.order is None
    reference = pin.buildModelFromXML(description.urdf, mimic=True)
    reduced = models.coupling.reduced
    assert list(reduced.names) == list(reference.names) and reduced.nq == 3
    rotor, ratios = description.config.actuation.rotor
    np.testing.assert_allclose(reduced.armature, rotor * np.array(ratios) ** 2, rtol=1e-15)
    np.testing.assert_array_equal(reduced.gravity.linear, [0, 0, -description.config.gravity])


def test_the_touchs_stylus_model_holds_the_arm_as_the_locked_model_does():
    description = describe("touch")
    models = pinocchio_models(description)
    stylus, order, arm = models.stylus, models.order, models.coupling.reduced
    names = ["joint1", "joint2", "joint3", *GIMBAL_JOINTS]
    assert stylus.nq == 6 and arm.nq == 3 and models.full.reduced.nq == 6
    assert list(order) == [stylus.joints[stylus.getJointId(n)].idx_q for n in names]
    np.testing.assert_array_equal(stylus.armature[order[:3]], arm.armature)
    locked_at = description.config.gimbal.locked_at
    rng = np.random.default_rng(16)
    sd, ad = stylus.createData(), arm.createData()
    for theta in rng.uniform(-0.5, 0.5, (5, 3)):
        q = np.zeros(6)
        q[order] = np.concatenate([theta, locked_at])
        zero6, zero3 = np.zeros(6), np.zeros(3)
        arm_torque = pin.rnea(arm, ad, theta, zero3, zero3)
        np.testing.assert_allclose(pin.rnea(stylus, sd, q, zero6, zero6)[order[:3]], arm_torque, rtol=0, atol=1e-12)
    # rooted at report_s: that frame is the stylus model's origin at the neutral configuration
    pin.framesForwardKinematics(stylus, sd, pin.neutral(stylus))
    assert sd.oMf[stylus.getFrameId("report_s")].isApprox(pin.SE3.Identity(), 1e-12)
