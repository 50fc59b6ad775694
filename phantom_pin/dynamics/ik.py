"""Phantom.inverse_kinematics: damped Newton iterations on Pinocchio's forward kinematics and
frame Jacobian of the model rooted at frame s, seeded on the requested elbow branch."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin

from phantom_pin._validation import wrap_angle
from phantom_pin.config.types import Kinematics
from phantom_pin.dynamics.fast import solve_spd
from phantom_pin.exceptions import UnreachableTargetError

#: Newton iterations and position tolerance (m).
ITERATIONS, TOLERANCE = 60, 1e-13
#: Damping (m^2) of the normal equations: small enough that Newton still converges on the
#: shell's boundaries, where the Jacobian is singular (1e-12 stalled there near 6e-13 m).
DAMPING = 1e-16
#: Largest Newton step (rad); seeds (theta2, theta3 in rad) for each elbow branch.
MAX_STEP = 0.3
#: cos(theta3 - theta2) within this of 0 counts as either branch (the shell's boundaries).
BRANCH_SLACK = 1e-5
SEEDS = {"report": ((0.35, 0.3), (0.9, 1.0)), "other": ((-0.35, -2.8), (0.9, -1.5))}


def solve_ik(model: pin.Model, data: pin.Data, tip: int, p: Kinematics, target: np.ndarray,
             branch: str) -> np.ndarray:
    """Angles (rad) that put the frame ``tip`` of ``model`` (rooted at frame s; ``p`` the
    configuration's lengths) at ``target`` (m, frame s) on ``branch`` (Phantom.inverse_kinematics,
    which checks the arguments)."""
    x, y, z = target.tolist()
    distance = math.hypot(x, y - p.l2, z + p.l1)  # from the shoulder (0, l2, -l1) in s
    if not abs(p.l1 - p.l2) * (1 - 1e-12) <= distance <= (p.l1 + p.l2) * (1 + 1e-12):
        raise UnreachableTargetError(
            f"{np.array2string(target, precision=4)} m is {distance:.4g} m from "
            f"the shoulder, outside the reachable shell [{abs(p.l1 - p.l2):.4f}, "
            f"{p.l1 + p.l2:.4f}] m", argument="position")
    sign = 1.0 if branch == "report" else -1.0
    for seed in SEEDS[branch]:
        theta = _newton(model, data, tip, (x, y, z), np.array([math.atan2(x, z + p.l1), *seed]))
        # the report's branch has the elbow open forwards, cos(theta3 - theta2) =
        # sin(alpha) >= 0; on the shell's boundaries (alpha = 0 or pi) both branches
        # meet, where Newton's angles are good to about sqrt(tolerance / l) ~ 1e-6 rad
        if theta is not None and sign * math.cos(theta[2] - theta[1]) > -BRANCH_SLACK:
            return wrap_angle(theta)
    raise UnreachableTargetError(
        f"no {branch}-branch solution found for {target} m", argument="position")


def _newton(model: pin.Model, data: pin.Data, tip: int, target: tuple[float, float, float],
            theta: np.ndarray) -> np.ndarray | None:
    """Damped Newton on the tip position from ``theta``; None if it does not converge.

    Each step solves the damped normal equations (J^T J + damping I) step = J^T error,
    J the tip point's (3, 3) Jacobian in s; in floats, which is 2x faster than NumPy on
    3-vectors."""
    tx, ty, tz = target
    for _ in range(ITERATIONS):
        # rows 0-2 of the LOCAL_WORLD_ALIGNED Jacobian: the tip point's velocity in s;
        # its columns a, b, c, one per joint
        jacobian = pin.computeFrameJacobian(model, data, theta, tip, pin.LOCAL_WORLD_ALIGNED)
        (a0, b0, c0), (a1, b1, c1), (a2, b2, c2) = jacobian[:3].tolist()
        x, y, z = data.oMf[tip].translation.tolist()
        ex, ey, ez = tx - x, ty - y, tz - z
        if math.hypot(ex, ey, ez) < TOLERANCE:
            return theta
        ab = a0 * b0 + a1 * b1 + a2 * b2
        ac = a0 * c0 + a1 * c1 + a2 * c2
        bc = b0 * c0 + b1 * c1 + b2 * c2
        normal = [[a0 * a0 + a1 * a1 + a2 * a2 + DAMPING, ab, ac],
                  [ab, b0 * b0 + b1 * b1 + b2 * b2 + DAMPING, bc],
                  [ac, bc, c0 * c0 + c1 * c1 + c2 * c2 + DAMPING]]
        gradient = (a0 * ex + a1 * ey + a2 * ez, b0 * ex + b1 * ey + b2 * ez,
                    c0 * ex + c1 * ey + c2 * ez)
        step = solve_spd(normal, gradient)
        if step is None:  # singular to rounding: LAPACK's LU, as before the float path
            step = np.linalg.solve(np.array(normal), gradient).tolist()
        largest = max(map(abs, step))
        scale = 1.0 if largest <= MAX_STEP else MAX_STEP / largest
        t0, t1, t2 = theta.tolist()
        theta = np.array([t0 + scale * step[0], t1 + scale * step[1], t2 + scale * step[2]])
    return None
