"""Independent references for the OpenHaptics tests (tests/interfaces/), and their shared helpers
(falling_posture, tips, framed, residuals).

- HDDEFINES: the values of SensAble's HD/hdDefines.h and hdScheduler.h (OpenHaptics 3.30), read
  at hhmai/PhantomAPI commit e01998c, include/HD/hdDefines.h, and SensAble's hdScheduler.h
  (public copies of the OpenHaptics 3.x headers), restated here as facts.
- pyopenhaptics_defines(): pyOpenHaptics 1.0.1's hd_define.py (PyPI), the second source, read
  from the installed package's file (importing the package would load libHD.so).
- gravity_and_jacobian(name, theta, gimbal): each model's gravity torques (N m) and tip Jacobian
  in frame s (m/rad) from a reference independent of phantom_pin's Phantom: the report's closed
  form for premium_1_5 (eqs 93-94, and R_st J^b_v of eq. 24), the tests' SymPy re-derivation of
  the CAD (tests/references/cad.py) with its Jacobian by central differences of the report's
  eq. 10 at the CAD's lengths, and Pinocchio alone on the Touch's committed six-joint URDF
  (tests/helpers.Six: the gimbal at its angles, the frame tip's Jacobian rotated into report_s).
"""

from __future__ import annotations

import functools
import importlib.util
from importlib import metadata
from pathlib import Path

import numpy as np
import pinocchio as pin

#: N m: |J^T F - gravity| at every tick (both sides exact up to rounding; measured below 1e-13)
TOLERANCE = 1e-9

HDDEFINES = {
    "HD_SUCCESS": 0x0000, "HD_INVALID_ENUM": 0x0100, "HD_INVALID_VALUE": 0x0101, "HD_INVALID_OPERATION": 0x0102,
    "HD_INVALID_INPUT_TYPE": 0x0103, "HD_BAD_HANDLE": 0x0104, "HD_WARM_MOTORS": 0x0200,
    "HD_EXCEEDED_MAX_FORCE": 0x0201, "HD_EXCEEDED_MAX_FORCE_IMPULSE": 0x0202, "HD_EXCEEDED_MAX_VELOCITY": 0x0203,
    "HD_FORCE_ERROR": 0x0204, "HD_DEVICE_FAULT": 0x0300, "HD_DEVICE_ALREADY_INITIATED": 0x0301,
    "HD_COMM_ERROR": 0x0302, "HD_COMM_CONFIG_ERROR": 0x0303, "HD_TIMER_ERROR": 0x0304, "HD_ILLEGAL_BEGIN": 0x0400,
    "HD_ILLEGAL_END": 0x0401, "HD_FRAME_ERROR": 0x0402, "HD_INVALID_PRIORITY": 0x0500, "HD_SCHEDULER_FULL": 0x0501,
    "HD_INVALID_LICENSE": 0x0600,
    "HD_CURRENT_BUTTONS": 0x2000, "HD_CURRENT_SAFETY_SWITCH": 0x2001, "HD_CURRENT_INKWELL_SWITCH": 0x2002,
    "HD_CURRENT_ENCODER_VALUES": 0x2010, "HD_CURRENT_POSITION": 0x2050, "HD_CURRENT_VELOCITY": 0x2051,
    "HD_CURRENT_TRANSFORM": 0x2052, "HD_CURRENT_ANGULAR_VELOCITY": 0x2053, "HD_CURRENT_JACOBIAN": 0x2054,
    "HD_CURRENT_JOINT_ANGLES": 0x2100, "HD_CURRENT_GIMBAL_ANGLES": 0x2150, "HD_LAST_BUTTONS": 0x2200,
    "HD_LAST_POSITION": 0x2250, "HD_LAST_VELOCITY": 0x2251, "HD_LAST_TRANSFORM": 0x2252,
    "HD_LAST_JOINT_ANGLES": 0x2300, "HD_LAST_GIMBAL_ANGLES": 0x2350, "HD_VERSION": 0x2500,
    "HD_DEVICE_MODEL_TYPE": 0x2501, "HD_DEVICE_DRIVER_VERSION": 0x2502, "HD_DEVICE_VENDOR": 0x2503,
    "HD_DEVICE_SERIAL_NUMBER": 0x2504, "HD_DEVICE_FIRMWARE_VERSION": 0x2505, "HD_MAX_WORKSPACE_DIMENSIONS": 0x2550,
    "HD_USABLE_WORKSPACE_DIMENSIONS": 0x2551, "HD_TABLETOP_OFFSET": 0x2552, "HD_INPUT_DOF": 0x2553,
    "HD_OUTPUT_DOF": 0x2554, "HD_CALIBRATION_STYLE": 0x2555, "HD_UPDATE_RATE": 0x2600,
    "HD_INSTANTANEOUS_UPDATE_RATE": 0x2601, "HD_NOMINAL_MAX_STIFFNESS": 0x2602, "HD_NOMINAL_MAX_DAMPING": 0x2609,
    "HD_NOMINAL_MAX_FORCE": 0x2603, "HD_NOMINAL_MAX_CONTINUOUS_FORCE": 0x2604, "HD_CURRENT_FORCE": 0x2700,
    "HD_CURRENT_TORQUE": 0x2701, "HD_CURRENT_JOINT_TORQUE": 0x2703, "HD_CURRENT_GIMBAL_TORQUE": 0x2704,
    "HD_LAST_FORCE": 0x2800, "HD_LAST_TORQUE": 0x2801, "HD_LAST_JOINT_TORQUE": 0x2802,
    "HD_LAST_GIMBAL_TORQUE": 0x2803, "HD_FORCE_OUTPUT": 0x4000, "HD_MAX_FORCE_CLAMPING": 0x4001,
    "HD_FORCE_RAMPING": 0x4002, "HD_SOFTWARE_FORCE_LIMIT": 0x4003, "HD_ONE_FRAME_LIMIT": 0x4004,
    "HD_MAX_SCHEDULER_PRIORITY": 65535, "HD_MIN_SCHEDULER_PRIORITY": 0, "HD_DEFAULT_SCHEDULER_PRIORITY": 32767,
    "HD_CALIBRATION_OK": 0x5000, "HD_CALIBRATION_NEEDS_UPDATE": 0x5001, "HD_CALIBRATION_NEEDS_MANUAL_INPUT": 0x5002,
    "HD_CALIBRATION_ENCODER_RESET": 1, "HD_CALIBRATION_AUTO": 2, "HD_CALIBRATION_INKWELL": 4,
    "HD_DEVICE_BUTTON_1": 1, "HD_DEVICE_BUTTON_2": 2, "HD_DEVICE_BUTTON_3": 4, "HD_DEVICE_BUTTON_4": 8,
    "HD_INVALID_HANDLE": 0xFFFFFFFF, "HD_TRUE": 1, "HD_FALSE": 0,
    # hdScheduler.h
    "HD_CALLBACK_DONE": 0, "HD_CALLBACK_CONTINUE": 1, "HD_WAIT_CHECK_STATUS": 0, "HD_WAIT_INFINITE": 1,
}
#: Where pyOpenHaptics 1.0.1 differs from SensAble's header: HD_INVALID_OPERATION is 0x0103 there
#: (HD_INVALID_INPUT_TYPE's value; it has no HD_INVALID_INPUT_TYPE), HD_EXCEEDED_MAX_FORCE is
#: spelled HD_EXCEED_MAX_FORCE, HD_DEFAULT_SCHEDULER_PRIORITY is a float (65535 / 2).
PYOPENHAPTICS_DIFFERS = {"HD_INVALID_OPERATION": 0x0103, "HD_DEFAULT_SCHEDULER_PRIORITY": 32767.5}
PYOPENHAPTICS_SPELLING = {"HD_EXCEEDED_MAX_FORCE": "HD_EXCEED_MAX_FORCE"}


def pyopenhaptics_defines() -> dict[str, object]:
    """pyOpenHaptics' hd_define.py's module namespace (its file, loaded alone)."""
    files = metadata.files("pyOpenHaptics") or []
    path = next(Path(str(f.locate())) for f in files if str(f).endswith("hd_define.py"))
    spec = importlib.util.spec_from_file_location("hd_define", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return vars(module)


@functools.cache
def _six():
    from helpers import Six
    return Six()


def _touch(theta: np.ndarray, gimbal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    six = _six()
    q = six.q(theta, gimbal)
    gravity = pin.computeGeneralizedGravity(six.model, six.data, q)[six.arm]
    pin.computeJointJacobians(six.model, six.data, q)
    pin.framesForwardKinematics(six.model, six.data, q)
    tip = pin.getFrameJacobian(six.model, six.data, six.model.getFrameId("tip"), pin.LOCAL_WORLD_ALIGNED)[:3]
    s = six.data.oMf[six.model.getFrameId("report_s")].rotation
    velocity_index = [six.model.joints[six.model.getJointId(f"joint{j}")].idx_v for j in range(1, 4)]
    return gravity, s.T @ tip[:, velocity_index]


def _tip(theta: np.ndarray, l1: float, l2: float) -> np.ndarray:
    """The report's eq. 10: the tip in frame s (m)."""
    t1, t2, t3 = theta
    r = l1 * np.cos(t2) + l2 * np.sin(t3)
    return np.array([r * np.sin(t1), l2 - l2 * np.cos(t3) + l1 * np.sin(t2), -l1 + r * np.cos(t1)])


def gravity_and_jacobian(name: str, theta: np.ndarray, gimbal: np.ndarray | None = None
                         ) -> tuple[np.ndarray, np.ndarray]:
    """(gravity torques (3,), N m; tip Jacobian in frame s (3, 3), m/rad) of the module's doc."""
    from phantom_pin.config import read
    from phantom_pin.report import closed_form

    theta = np.asarray(theta, dtype=float)
    if name == "touch":
        return _touch(theta, np.zeros(3) if gimbal is None else np.asarray(gimbal, dtype=float))
    config = read(name)
    if name == "premium_1_5":
        report = config.report
        pose = closed_form.forward_kinematics(theta, report)
        return closed_form.gravity(theta, report), pose[:3, :3] @ closed_form.body_jacobian(theta, report)[:3]
    from references import cad as cad_reference
    k, h = config.kinematics, 1e-6
    jacobian = np.column_stack([(_tip(theta + h * e, k.l1, k.l2) - _tip(theta - h * e, k.l1, k.l2)) / (2 * h)
                                for e in np.eye(3)])
    return cad_reference.gravity(theta), jacobian


def falling_posture(name, seed=49):
    """A seeded posture inside the stops where gravity beats static friction (some joint's gravity
    torque at least 3 times its breakaway torque) and the tip Jacobian is far from singular."""
    from phantom_pin.config import read
    from phantom_pin.config.sampling import random_states

    config = read(name)
    for theta in random_states(config.limits, 200, seed=seed)[0]:
        gravity, jacobian = gravity_and_jacobian(name, theta)
        if np.max(np.abs(gravity) / np.array(config.actuation.friction.coulomb)) > 3 and \
                abs(np.linalg.det(jacobian)) > 1e-4:
            return theta
    raise AssertionError("no posture")


def tips(name, theta):
    if name == "touch":
        return np.array([_six().pose(t, np.zeros(3), "tip")[:3, 3] for t in theta])
    from phantom_pin.config import read

    k = read(name).kinematics
    return np.array([_tip(t, k.l1, k.l2) for t in theta])


def framed(record):
    """The ticks in which a frame ended: the scheduler ticks without a frame (its command zero)
    before a callback is scheduled and between the callback's last tick and hdStopScheduler."""
    keep = record["framed"] == 1
    ticks = np.flatnonzero(keep)
    assert len(ticks) and (np.diff(ticks) == 1).all()      # frameless ticks only before and after
    return {k: v[keep] for k, v in record.items()}


def residuals(name, record, shift=0):
    """|J^T F - gravity| (N m) per tick, the command of tick k against the state of tick k - shift."""
    theta = np.column_stack([record[f"theta{i}"] for i in (1, 2, 3)])
    force = np.column_stack([record[f"force{i}"] for i in (1, 2, 3)])
    torque = np.column_stack([record[f"torque{i}"] for i in (1, 2, 3)])
    out = []
    for k in range(shift, len(theta)):
        gravity, jacobian = gravity_and_jacobian(name, theta[k - shift])
        applied = jacobian.T @ force[k] + torque[k] * np.array([-1.0, 1.0, 1.0]) / 1000.0
        out.append(np.abs(applied - gravity).max())
    return np.array(out)
