"""The header's functions in OpenHaptics' terms (codegen/servo.py), compiled strictly and
loaded through ctypes: the angles' and torques' maps against the published conventions, the
servo loop's compensation and the transparent joint torque against Pinocchio and the Compensator."""

import ctypes

import numpy as np
import pytest

from helpers import build, call, generated
from phantom_pin import describe
from phantom_pin.config import models
from phantom_pin.config.sampling import random_states


def test_openhaptics_helpers_follow_the_published_conventions(tmp_path):
    """The header's OpenHaptics conversions against the published conventions written out here,
    not against phantom_pin.interfaces.conventions (the same convention twice). Angles: Ubitrack/
    component_haptic_calibration's PhantomForwardKinematics.h lines 101-103 put the tip of
    OpenHaptics' angles a at x = -(l1 c2 + l2 s3) s1, y = l1 s2 - l2 c3 + l2, z = -l1 + (l1 c2 +
    l2 s3) c1 (l1 = l2 = 133.35 mm, its default): the header's tip at theta_from_openhaptics(a)
    is there (1e-12 m), and theta = (-a1, a2, a3) exactly. Torques: SensAble's CommandJointTorque
    sample gives HD_CURRENT_JOINT_TORQUE in mN m on OpenHaptics' own angles, so it does tau's
    power on their rates (1e-9 relative) and equals 1000 (-tau1, tau2, tau3) exactly; a spring
    restoring theta is the sample's restoring spring, torque = k (0 - a) with k > 0."""
    library = build(generated("touch"), tmp_path)
    rng = np.random.default_rng(5)
    angles = rng.uniform([-0.98, 0.0, 0.0], [0.98, 1.75, 2.0], (50, 3))   # inside the Touch's stops
    theta = call(library, "theta_from_openhaptics", 3, angles)
    assert np.array_equal(theta, np.column_stack([-angles[:, 0], angles[:, 1], angles[:, 2]]))
    length = 0.13335
    s1, c1, s2, c2, s3, c3 = (f(angles[:, k]) for k in range(3) for f in (np.sin, np.cos))
    ubitrack = np.column_stack([-(length * c2 + length * s3) * s1, length * s2 - length * c3 + length,
                                -length + (length * c2 + length * s3) * c1])
    assert np.abs(call(library, "tip_position", 3, theta) - ubitrack).max() < 1e-12
    tau, rates = rng.normal(0, 1, (50, 3)), rng.normal(0, 1, (50, 3))   # N m; OpenHaptics' angle rates
    torque = call(library, "openhaptics_torque_from_tau", 3, tau)
    assert np.array_equal(torque, 1000 * np.column_stack([-tau[:, 0], tau[:, 1], tau[:, 2]]))
    theta_rates = np.column_stack([-rates[:, 0], rates[:, 1], rates[:, 2]])   # d theta / dt of d a / dt
    power_mw = np.einsum("ni,ni->n", torque, rates)
    assert np.abs(power_mw - 1000 * np.einsum("ni,ni->n", tau, theta_rates)).max() < 1e-9 * np.abs(power_mw).max()
    restoring = call(library, "openhaptics_torque_from_tau", 3, -0.5 * theta)   # a spring to theta = 0
    assert np.all(restoring * angles <= 0) and np.all(restoring[angles != 0] != 0)  # the sample's: to a = 0


#: The servo loop's own terms (docs/servo-loop.md, "In your servo loop"): per state a, b = angles.
SERVO_SHIM = """#include "model.h"
void servo(int n, const double *a, const double *g, const double *r, double *out) {
    int k; for (k = 0; k < n; ++k) {
        phantom_openhaptics_force(a + 3 * k, g + 3 * k, out + 12 * k);
        phantom_openhaptics_joint_torque(a + 3 * k, g + 3 * k, out + 12 * k + 3);
        phantom_openhaptics_force_friction(a + 3 * k, g + 3 * k, r + 3 * k, out + 12 * k + 6);
        phantom_openhaptics_joint_torque_friction(a + 3 * k, g + 3 * k, r + 3 * k, out + 12 * k + 9); } }
"""


@pytest.mark.parametrize("name", models())
def test_the_servo_loop_functions_compensate_gravity_and_friction(name, tmp_path):
    """NAME_openhaptics_force and _joint_torque (and their _friction forms), compiled strictly,
    on 200 seeded states inside the stops (the Touch's gimbal inside its ranges, OpenHaptics'
    angles a = (-theta1, theta2, theta3)): J^T F and the joint torques on theta equal the
    gravity of references independent of Phantom (tests/references/openhaptics.py: the closed
    form, the CAD's re-derivation, the Touch's six-joint URDF in Pinocchio) to 1e-9 N m, plus the
    friction law (actuation.yaml's numbers) at the rates given; NAME_STYLUS says whether the
    model has a gimbal."""
    from references.openhaptics import gravity_and_jacobian
    text = generated(name)
    library = build(text, tmp_path, SERVO_SHIM)
    config = describe(name).config
    n = 200
    theta = random_states(config.limits, n, seed=61)[0]
    rng = np.random.default_rng(62)
    gimbal = np.zeros((n, 3)) if config.gimbal is None else \
        rng.uniform(config.gimbal.lower, config.gimbal.upper, (n, 3))
    rates = rng.normal(0, 1, (n, 3))
    sign = np.array([-1.0, 1.0, 1.0])
    out = np.empty((n, 12))
    pointer = ctypes.POINTER(ctypes.c_double)
    arrays = [np.ascontiguousarray(x) for x in (sign * theta, gimbal, rates)]
    library.servo(ctypes.c_int(n), *(x.ctypes.data_as(pointer) for x in arrays), out.ctypes.data_as(pointer))
    law = config.actuation.friction
    for k in range(n):
        gravity, jacobian = gravity_and_jacobian(name, theta[k], None if config.gimbal is None else gimbal[k])
        friction = np.array(law.viscous) * sign * rates[k] + np.array(law.coulomb) * np.sign(sign * rates[k])
        assert np.abs(jacobian.T @ out[k, :3] - gravity).max() <= 1e-9
        assert np.abs(sign * out[k, 3:6] / 1000 - gravity).max() <= 1e-9
        assert np.abs(jacobian.T @ out[k, 6:9] - gravity - friction).max() <= 1e-9
        assert np.abs(sign * out[k, 9:12] / 1000 - gravity - friction).max() <= 1e-9
    assert f"#define PHANTOM_STYLUS {int(config.gimbal is not None)}" in text


TRANSPARENT_SHIM = """#include "model.h"
void transparent(int n, const double *a, double kappa, double dead_band, double *out) {
    phantom_estimator e; const double g[3] = {0.0, 0.0, 0.0}; int k;
    phantom_estimator_init(&e, 1000.0, 20.0);
    for (k = 0; k < n; ++k) {
        phantom_estimator_update(&e, a + 3 * k);
        phantom_openhaptics_joint_torque_transparent(a + 3 * k, g, &e, kappa, dead_band, out + 3 * k); } }
"""


@pytest.mark.parametrize("name", models())
def test_the_transparent_joint_torque_is_the_compensators(name, tmp_path):
    """The header's estimator and NAME_openhaptics_joint_torque_transparent, over 300 ticks of a
    seeded smooth motion (OpenHaptics' angles, 1 kHz, with a pause the dead band must see), give
    the pyOpenHaptics Compensator's joint torques with gravity, friction and kappa = 0.5 of the
    inertia, tick by tick, to 1e-9 relative: one estimator and one law in two languages (the
    stylus at locked_at, where the header's M and C hold)."""
    from phantom_pin.interfaces.openhaptics import Compensator
    library = build(generated(name), tmp_path, TRANSPARENT_SHIM)
    t = np.arange(300) / 1000.0
    rng = np.random.default_rng(71)
    base, amplitude = np.array([0.1, 0.4, 0.5]), rng.uniform(0.05, 0.2, 3)
    angles = base + amplitude * np.sin(2 * np.pi * 1.5 * np.minimum(t, 0.15)[:, None] + rng.uniform(0, 1, 3))
    out = np.empty((len(t), 3))
    pointer = ctypes.POINTER(ctypes.c_double)
    a = np.ascontiguousarray(angles)
    library.transparent(ctypes.c_int(len(t)), a.ctypes.data_as(pointer), ctypes.c_double(0.5), ctypes.c_double(0.01),
                        out.ctypes.data_as(pointer))
    compensate = Compensator(name, "joint_torque", ("gravity", "friction", "inertia"), kappa=0.5)
    gimbal = None if describe(name).config.gimbal is None else [0.0, 0.0, 0.0]
    python = np.array([compensate.torque(x, gimbal) for x in angles]) * np.array([-1.0, 1.0, 1.0]) * 1000.0
    assert np.abs(out - python).max() <= 1e-9 * np.abs(python).max()
    assert np.abs(out[200:] - out[-1]).max() < np.abs(out[100:150] - out[-1]).max()   # the pause: inertia off
