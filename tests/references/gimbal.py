"""Independent reference for the Touch's stylus gimbal: Ubitrack's forward kinematics of
OpenHaptics' six angles, transcribed, and the gimbal links' load on the arm (potential, mass
matrix) from the rigid-body laws, with complex-step derivatives of that kinematics and each
link's mass properties about the gimbal centre integrated by SymPy (touch_reference). Nothing
here reads the project's code; the lengths are Ubitrack's (l1 = l2 = 0.13335 m) and g the
standard gravity, as config/touch states them."""

from __future__ import annotations

import numpy as np

from references import touch as touch_reference

L1 = L2 = 0.13335   # m, Ubitrack's PhantomForwardKinematics.xml "defaults to Phantom Omni: 133.35mm"
G = 9.80665         # m/s^2, standard gravity (config/touch's)
H = 1e-30           # the complex step


# -- Ubitrack's forward kinematics of OpenHaptics' angles, transcribed (PhantomForwardKinematics.h,
# component_haptic_calibration bf778bb, lines 99-117; O1..O3 joint angles, O4..O6 raw gimbal
# angles; m[0..8] row-major). Written with numpy's sin and cos, so that it takes complex angles.

def ubitrack(o: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(position (3,), rotation (3, 3)) of OpenHaptics' six angles ``o``, in OpenHaptics'
    frame (Ubitrack's calibration at identity, its origin offset 0)."""
    l1, l2 = L1, L2
    s1, s2, s3, s4, s5, s6 = np.sin(o)
    c1, c2, c3, c4, c5, c6 = np.cos(o)
    position = np.array([-(l1 * c2 + l2 * s3) * s1, l1 * s2 - l2 * c3 + l2, -l1 + (l1 * c2 + l2 * s3) * c1])
    m = np.array([
        (-(s1 * c3 * c4 - s4 * c1) * s5 - s1 * s3 * c5) * s6 + (s1 * s4 * c3 + c1 * c4) * c6,
        ((s1 * c3 * c4 - s4 * c1) * s5 + s1 * s3 * c5) * c6 + (s1 * s4 * c3 + c1 * c4) * s6,
        (-s1 * c3 * c4 + s4 * c1) * c5 + s1 * s3 * s5,
        (s3 * s5 * c4 - c3 * c5) * s6 - s3 * s4 * c6,
        (-s3 * s5 * c4 + c3 * c5) * c6 - s3 * s4 * s6,
        s3 * c4 * c5 + s5 * c3,
        (-(-s1 * s4 - c1 * c3 * c4) * s5 + s3 * c1 * c5) * s6 + (s1 * c4 - s4 * c1 * c3) * c6,
        ((-s1 * s4 - c1 * c3 * c4) * s5 - s3 * c1 * c5) * c6 + (s1 * c4 - s4 * c1 * c3) * s6,
        (s1 * s4 + c1 * c3 * c4) * c5 - s3 * s5 * c1])
    return position, m.reshape(3, 3)


def openhaptics(theta: np.ndarray, gimbal: np.ndarray) -> np.ndarray:
    """OpenHaptics' six angles of the report's theta and the raw gimbal angles: the joint
    angles are (-theta1, theta2, theta3) (phantom_pin.interfaces.conventions' module doc)."""
    return np.array([-theta[0], theta[1], theta[2], *gimbal])


def link_rotations(theta: np.ndarray, gimbal: np.ndarray) -> list[np.ndarray]:
    """The yaw, pitch and stylus links' rotations in frame s: the stylus's (Ubitrack's) with the
    later gimbal angles at zero (each link turns with the joints up to its own)."""
    return [ubitrack(openhaptics(theta, np.array([*gimbal[:k], *np.zeros(3 - k)])))[1] for k in (1, 2, 3)]


def step(x: np.ndarray, k: int, h: complex) -> np.ndarray:
    out = x.astype(complex)
    out[k] += h
    return out



def derivative(function, x: np.ndarray, k: int) -> np.ndarray:
    """d function / d x_k by a complex step (exact to rounding for analytic functions)."""
    return np.imag(function(step(x, k, H * 1j))) / H


def gimbal_potential(theta: np.ndarray, gimbal: np.ndarray) -> complex:
    """The gimbal links' potential energy (J) above frame s's origin: sum of m g (height of the
    gimbal centre) + g (R h)_y, h each link's first moment about the centre (y is up)."""
    position, _ = ubitrack(openhaptics(theta, gimbal))
    energy = 0j
    for name, rotation in zip(touch_reference.GIMBAL_REFERENCE, link_rotations(theta, gimbal)):
        reference = touch_reference.GIMBAL_REFERENCE[name]
        energy += G * (reference["mass"] * position[1] + (rotation @ np.array(reference["first"]))[1])
    return energy


def gimbal_gravity(theta: np.ndarray, gimbal: np.ndarray) -> np.ndarray:
    """The gimbal links' gravity torques on theta1..theta3 (N m): the potential's gradient."""
    g = np.asarray(gimbal, complex)
    return np.array([derivative(lambda t: gimbal_potential(t, g), np.asarray(theta, float), k) for k in range(3)])


def gimbal_mass_matrix(theta: np.ndarray, gimbal: np.ndarray) -> np.ndarray:
    """The gimbal links' share of the arm's mass matrix (kg m^2) with the gimbal held at
    ``gimbal``: sum of m Jc^T Jc + the cross terms of the first moment + Jw^T R J R^T Jw."""
    theta, gimbal = np.asarray(theta, float), np.asarray(gimbal, float)
    rotations = link_rotations(theta, gimbal)
    derivatives = []
    for k in range(3):
        shifted = step(theta, k, H * 1j)
        derivatives.append((ubitrack(openhaptics(shifted, gimbal))[0].imag / H,
                            [r.imag / H for r in link_rotations(shifted, gimbal)]))
    total = np.zeros((3, 3))
    for index, name in enumerate(touch_reference.GIMBAL_REFERENCE):
        ref = touch_reference.GIMBAL_REFERENCE[name]
        mass, first, second = ref["mass"], np.array(ref["first"]), ref["second"]
        about_centre = np.diag([second["xx"], second["yy"], second["zz"]])  # products vanish
        rotation = rotations[index]
        jv, jw = np.zeros((3, 3)), np.zeros((3, 3))
        for k, (dp, drs) in enumerate(derivatives):
            omega = drs[index] @ rotation.T
            jw[:, k] = omega[2, 1], omega[0, 2], omega[1, 0]
            jv[:, k] = dp  # the gimbal centre's velocity
        # a body's kinetic energy about a moving point c: 1/2 m vc^2 + vc . (w x R h) + 1/2 w^T R J R^T w
        h = rotation @ first
        cross_h = np.array([[0, -h[2], h[1]], [h[2], 0, -h[0]], [-h[1], h[0], 0]])
        coupling = -jv.T @ cross_h @ jw
        total += mass * jv.T @ jv + coupling + coupling.T + jw.T @ rotation @ about_centre @ rotation.T @ jw
    return total
