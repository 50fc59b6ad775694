"""Independent reference for the drivers: each public driver's own formulas, transcribed from
its source lines (not from our profiles), and the Touch's tip Jacobian and gravity from
Ubitrack's kinematics (complex-step derivatives), the report's closed form and the gimbal's
reference load. Nothing here reads phantom_pin's profiles or forces."""

from __future__ import annotations

import math

import numpy as np
import yaml

from helpers import CONFIG_DIR
from references.gimbal import L1, L2, derivative, gimbal_gravity, openhaptics, ubitrack

TOUCH = CONFIG_DIR.parent / "touch"
LIMITS = yaml.safe_load((TOUCH / "joint_limits.yaml").read_text())["stops"]
RANGES = yaml.safe_load((TOUCH / "gimbal.yaml").read_text())["joints"]
PI = math.pi


# -- from each driver's message to HD_CURRENT_FORCE (N, OpenHaptics' frame), its own formula ------
def geomagic_touch_ros2(message) -> np.ndarray:
    """IvoD1998/Geomagic_Touch_ROS2@cd0cdba omni_common/src/omni_state.cpp 320-325 (the stylus
    at rest: the damping of 189-191 is 0): hdSetDoublev(HD_CURRENT_FORCE, (f.x, f.z, -f.y))."""
    f = message.force
    return np.array([f.x, f.z, -f.y])


def sawsensablephantom(message) -> np.ndarray:
    """jhu-saw/sawSensablePhantom@7ddd575 mtsSensableHD.cpp 327-356: the wrench's force as it is
    (OpenHaptics' axes; viscosity 0 by default), its norm clamped to m_max_force = 2 N (71)."""
    f = message.wrench.force
    force = np.array([f.x, f.y, f.z])
    norm = np.linalg.norm(force)
    return force * (2.0 / norm) if norm > 2.0 else force


def phantom_touch_ros2(message) -> np.ndarray:
    """kinisi-robotics/phantom_touch_ros2@2bf5b20 hd++.cpp 138-145: the Vector3 as it is."""
    return np.array([message.x, message.y, message.z])


def touch_ros2_control(message) -> np.ndarray:
    """CalaW/touch_ros2_control@e1e181e device_transforms.hpp 19-44 and touch_driver_node.cpp
    176-199, 231-252 (at its start-up position, at rest: spring and damper 0): F_OH = (F_R.y,
    F_R.z, F_R.x); non-finite components 0; the norm clamped to max_force, 8 N by default (278)."""
    f = message.wrench.force
    force = np.array([f.y, f.z, f.x])
    force = np.where(np.isfinite(force), force, 0.0)
    norm = np.linalg.norm(force)
    return force * (8.0 / norm) if norm > 8.0 else force


def geomagic_touch_x_ros2(message) -> np.ndarray:
    """RViMLab/geomagic_touch_x_ros2@57da5c9 device.cpp 42-65: the Wrench's force as it is."""
    f = message.force
    return np.array([f.x, f.y, f.z])


FORCE = {"geomagic_touch_ros2": geomagic_touch_ros2, "sawsensablephantom": sawsensablephantom,
         "phantom_touch_ros2": phantom_touch_ros2, "touch_ros2_control": touch_ros2_control,
         "geomagic_touch_x_ros2": geomagic_touch_x_ros2}


# -- each driver's joint_states of OpenHaptics' raw angles a (arm) and g (gimbal), rad ------------
# The waist's sign, read at each driver's source (the commit each profile cites is its default
# branch's newest, checked 2026-12-03): -a1 in the fsuarez6 lineage and sawSensablePhantom, +a1
# in kinisi's, CalaW's and RViMLab's drivers.
def published(profile: str, a: np.ndarray, g: np.ndarray) -> tuple[list[str], list[float]]:
    """(names, positions) as each driver publishes them (sources in the comments)."""
    six = ["waist", "shoulder", "elbow", "yaw", "pitch", "roll"]
    if profile == "geomagic_touch_ros2":
        # IvoD1998/Geomagic_Touch_ROS2@cd0cdba (stevens-armlab@2e4b1f5 the same lines) omni_state.cpp:
        # 286 and 288 read HD_CURRENT_JOINT_ANGLES and HD_CURRENT_GIMBAL_ANGLES, 343-347 store
        # thetas = (0, a1, a2, a3 - a2, g1, g2, g3), 228-238 publish -thetas[1], thetas[2],
        # thetas[3], -thetas[4] + pi, -thetas[5] - 3 pi / 4, -thetas[6] - pi (bharatm11@34e9fac: 236,
        # 296-300, 183-193)
        return six, [-a[0], a[1], a[2] - a[1], -g[0] + PI, -g[1] - 3 * PI / 4, -g[2] - PI]
    if profile == "sawsensablephantom":
        # jhu-saw/sawSensablePhantom@7ddd575 core/components/code/mtsSensableHD.cpp 312-315 read the
        # angles, 418-419 q[0] = -q[0]; q[2] -= q[1]; 421-423 the gimbal as read
        return six, [-a[0], a[1], a[2] - a[1], *g]
    if profile in ("phantom_touch_ros2", "touch_ros2_control"):
        # kinisi-robotics/phantom_touch_ros2@2bf5b20 phantom_touch_control/src/hd++.cpp 257-268 (the
        # angles as read, angles[2] -= angles[1]), published as they are by
        # phantom_touch_control_node.cpp 215 and 314; CalaW/touch_ros2_control@e1e181e
        # touch_hardware/src/touch_driver_node.cpp 169 reads them, device_transforms.hpp 77-87
        # (a1, a2, a3 - a2, g1, g2, g3), touch_driver_node.cpp 377-378 publish them
        return six, [a[0], a[1], a[2] - a[1], *g]
    if profile == "geomagic_touch_x_ros2":
        # RViMLab/geomagic_touch_x_ros2@57da5c9 src/device.cpp 54-55 read, geomagic_touch_x_component.cpp
        # 103 names, 161-162 and 177 publish the angles as read: raw, elbow absolute
        return [f"joint_angle_{k}" for k in (1, 2, 3)] + [f"gimbal_angle_{k}" for k in (1, 2, 3)], [*a, *g]
    raise KeyError(profile)



# -- the Touch: the tip's position Jacobian in frame s and the gravity torques ------------------------
def tip_jacobian(theta: np.ndarray) -> np.ndarray:
    """d(gimbal centre in frame s)/d(theta) (m/rad): complex steps of Ubitrack's position of
    OpenHaptics' angles (-theta1, theta2, theta3)."""
    def position(t):
        return ubitrack(np.array([-t[0], t[1], t[2], 0, 0, 0], dtype=complex))[0]
    return np.column_stack([derivative(position, np.asarray(theta, dtype=float), k) for k in range(3)])


def gravity(theta: np.ndarray, gimbal: np.ndarray, report) -> np.ndarray:
    """The Touch's gravity torques (N m): the report's closed form with the Touch's numbers and
    the gimbal's links at the given angles (gimbal_reference)."""
    from phantom_pin import closed_form

    return closed_form.gravity(theta, report) + gimbal_gravity(theta, gimbal)


def stylus_rotation(theta: np.ndarray, gimbal: np.ndarray) -> np.ndarray:
    """The stylus frame's rotation in frame s (Ubitrack's m[0..8])."""
    return ubitrack(openhaptics(theta, gimbal))[1]


#: base_link <- frame s rotation (the macro's frame: the report's x, y, z along base_link's y, z, x).
BASE_FROM_S = np.array([[0.0, 0, 1], [1, 0, 0], [0, 1, 0]])


def states(n: int, seed: int, margin: float = 0.05) -> tuple[np.ndarray, np.ndarray]:
    """``n`` seeded (theta, g) inside the Touch's stops (``margin`` rad inside) and gimbal ranges."""
    rng = np.random.default_rng(seed)
    joints = ("joint1", "joint2", "joint3")
    lower = np.array([LIMITS[j]["lower"] for j in joints]) + margin
    upper = np.array([LIMITS[j]["upper"] for j in joints]) - margin
    theta = rng.uniform(lower, upper, (20 * n, 3))
    keep = ((theta[:, 1] - theta[:, 2] <= LIMITS["theta2_minus_theta3_max"] - margin)
            & (theta[:, 2] - theta[:, 1] <= LIMITS["theta3_minus_theta2_max"] - margin))
    theta = theta[keep][:n]
    names = ("joint4", "joint5", "joint6")
    g = rng.uniform([RANGES[j]["lower"] for j in names], [RANGES[j]["upper"] for j in names], (n, 3))
    return theta, g


__all__ = ["FORCE", "L1", "L2", "BASE_FROM_S", "published", "tip_jacobian", "gravity", "stylus_rotation", "states"]


# -- each driver's state topics (beside the joint states), its own formulas of OpenHaptics' values -----
def _ry(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def _rx(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


_B = np.array([[0.0, 0, 1], [1, 0, 0], [0, 1, 0]])   # CalaW's REP-103 basis: x = z_OH, y = x_OH, z = y_OH


def hdu_quaternion(stored: np.ndarray) -> tuple[float, float, float, float]:
    """(w, x, y, z) of hduQuaternion::fromRotationMatrix of a stored 3x3 R[i][j]
    (danepowell/openhaptics@2ce9a48 usr/share/3DTouch/libsrc/HDU/hduQuaternion.cpp 161-200)."""
    r = stored
    trace = r[0][0] + r[1][1] + r[2][2]
    if trace > 0.0:
        root = math.sqrt(trace + 1.0)
        w, root = 0.5 * root, 0.5 / root
        return w, (r[1][2] - r[2][1]) * root, (r[2][0] - r[0][2]) * root, (r[0][1] - r[1][0]) * root
    i = 0
    if r[1][1] > r[0][0]:
        i = 1
    if r[2][2] > r[i][i]:
        i = 2
    j, k = (1, 2, 0)[i], (1, 2, 0)[(1, 2, 0)[i]]
    root = math.sqrt(r[i][i] - r[j][j] - r[k][k] + 1.0)
    quat = [0.0, 0.0, 0.0]
    quat[i] = 0.5 * root
    root = 0.5 / root
    quat[j], quat[k] = (r[i][j] + r[j][i]) * root, (r[i][k] + r[k][i]) * root
    return (r[j][k] - r[k][j]) * root, quat[0], quat[1], quat[2]


def quaternion_rotation(w: float, x: float, y: float, z: float) -> np.ndarray:
    """The rotation (column vectors) of a unit quaternion as geometry_msgs/Quaternion holds it."""
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def geomagic_pose(t: np.ndarray, r: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """omni_state.cpp 284-301 and 241-249 (units mm): hduMatrix transform holds HD_CURRENT_TRANSFORM's
    16 numbers row by row (hduMatrix.h 43-44, 110-122): transform[i][j] = T[j][i], the translation in
    its last row; position (transform[3][0], -transform[3][2], transform[3][1]) / 1000; orientation
    hduQuaternion(rotation_offset * rotation), rotation_offset built row by row (a1..a16, hduMatrix.h
    46-65), `*` the plain product (hduGenericMatrix.h 261-267)."""
    transform = np.eye(4)
    transform[:3, :3], transform[3, :3] = r.T, t     # T^T of T = [[R, t], [0, 1]]
    offset = np.array([[0.0, -1, 0], [1, 0, 0], [0, 0, 1]])
    w, x, y, z = hdu_quaternion(offset @ transform[:3, :3])
    return np.array([transform[3][0], -transform[3][2], transform[3][1]]), quaternion_rotation(w, x, y, z)
#: topic -> (kind, formula of (t_OH m, R_OH) or (v_OH m/s, w_OH rad/s)), as each driver writes it
STATE = {
    # mtsSensableHD.cpp 401-404, 302-306: HD_CURRENT_TRANSFORM in m, OH axes; HD_CURRENT_VELOCITY / 1000
    "/arm/measured_cp": ("pose", lambda t, r: (t, r)),
    "/arm/measured_cv": ("twist", lambda v, w: (v, w)),
    # device_transforms.hpp 46-75, 111-114: B t, B R B^T; B v, B w
    "/touch/state/pose": ("pose", lambda t, r: (_B @ t, _B @ r @ _B.T)),
    "/touch/state/twist": ("twist", lambda v, w: (_B @ v, _B @ w)),
    # phantom_touch_control_node.cpp 267-280, hd++.cpp 194-200: t, R Ry(pi/2) Rx(-pi/2)
    "/pose_stylus_current": ("pose", lambda t, r: (t, r @ _ry(PI / 2) @ _rx(-PI / 2))),
    # omni_state.cpp 241-249, 284-301 (above)
    "/phantom/pose": ("pose", geomagic_pose),
    # geomagic_touch_x_component.cpp 184-196: HD_CURRENT_VELOCITY / 1000, HD_CURRENT_ANGULAR_VELOCITY
    "/geomagic_touch_x/twist": ("twist", lambda v, w: (v, w)),
}
