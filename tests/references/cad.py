"""Independent reference for the configuration premium_1_5_cad: the joint-space mass matrix
and gravity torque of the PHANToM Premium 1.5 with mahilab/Phantom's CAD mass properties,
derived here with SymPy from mahilab's RAW numbers in mahilab's OWN frames.

Nothing is read from the project's YAML or code: the constants below are transcribed from
mahilab/Phantom (Rice University MAHI Lab), cpp/src/PhantomModel.hpp, and the frames are the
Denavit-Hartenberg chains of its matlab/dynamics.m (Craig's modified convention, rows
[a, alpha, d, theta]):

    chain 1 (upper arm BE, forearm A):  [0, 0, 0, q1], [0, pi/2, 0, q2], [l1, 0, 0, q3 - q2]
    chain 2 (crank DF, lower bar C):    [0, 0, 0, q1], [0, pi/2, 0, q3 - pi/2], [l3, 0, 0, q2 - q3]

with the turret G on frame 1, BE on chain 1's frame 2, A on chain 1's frame 3 (the elbow), DF
on chain 2's frame 2, C on chain 2's frame 3 (the crank pin). mahilab's q1..q3 are our
theta1..theta3 (its forward kinematics is eq 10 in base_link; docs/cad.md).

The Lagrangian is built from the kinetic and potential energy of each body. Each body's
angular velocity is read off its own rotation matrix, omega_body^ = R^T dR/dt with
dR/dt = sum_i dR/dq_i dq_i/dt: this is the TRUE rate of every DH row (dq3/dt - dq2/dt for the
row q3 - q2, dq3/dt for q3 - pi/2, dq2/dt - dq3/dt for q2 - q3), not mahilab's
compute_energies.m, which gives row i the rate dq_i/dt (docs/cad.md). The motors' reflected
rotor inertia J_mot Eta_i^2 is added on the diagonal, as mahilab's step_dynamics does.

    mass_matrix(theta) -> (3, 3) kg m^2,  gravity(theta) -> (3,) N m (dV/dtheta)

both lambdified once, on first use. ``python tests/references/cad.py`` runs the self-check
against a purely numeric model of the links in our YAML (see ``_self_check``).
"""

from __future__ import annotations

import functools

import numpy as np
import sympy as sp

# --- mahilab/Phantom, cpp/src/PhantomModel.hpp, transcribed (SI units) --------------------
L1, L2, L3 = 0.209550, 0.169545, 0.031750        # l1, l2, l3 (m)
GRAVITY = 9.80665                                  # g (m/s^2), along -z of mahilab's frame {0}
J_MOT = 1.08e-06                                   # J_mot (kg m^2), rotor inertia
ETA = (13.3, 11.2, 11.2)                           # Eta, transmission ratios
#: body: (mass m_*, centre of mass Pc_* in its DH frame, Ic_* = (xx, xy, xz, yy, yz, zz) about
#: the COM in the DH frame, with SolidWorks' POSITIVE products xy = +integral(x y dm):
#: dynamics.m builds the tensor [[xx, -xy, -xz], [-xy, yy, -yz], [-xz, -yz, zz]]).
BODIES = {
    "a": (0.026220, (0.00002423, -0.05237892, 0.0),
          (6.029e-05, 0.0, 0.0, 5.7e-07, 0.0, 6.004e-05)),
    "c": (0.026146, (0.0, 0.10477739, 0.0),
          (0.00013177, 0.0, 0.0, 8.9e-07, 0.0, 0.00013138)),
    "be": (0.267840, (-0.03518875, -0.00006280, 0.00232416),
           (0.0001133, 4.1e-07, -2.296e-05, 0.00091667, 4.8e-07, 0.00082222)),
    "df": (0.215420, (-0.05153541, 0.00060903, 0.00402873),
           (0.0001214, -3.2e-07, -7.45e-06, 0.00026133, 3.23e-06, 0.00015823)),
    "g": (0.361590, (-0.01048563, 0.01396387, -0.05380827),
          (0.0015202, 5.838e-05, 0.00018147, 0.0012112, 0.00023832, 0.00093887)),
}

_Q = sp.symbols("q1:4", real=True)
_QD = sp.symbols("qd1:4", real=True)


def _dh(a: float, alpha: sp.Expr, d: float, theta: sp.Expr) -> sp.Matrix:
    """Craig's modified DH transform: Rot_x(alpha) Trans_x(a) Rot_z(theta) Trans_z(d)."""
    ca, sa, ct, st = sp.cos(alpha), sp.sin(alpha), sp.cos(theta), sp.sin(theta)
    return sp.Matrix([[ct, -st, 0, a],
                      [st * ca, ct * ca, -sa, -sa * d],
                      [st * sa, ct * sa, ca, ca * d],
                      [0, 0, 0, 1]])


def _frames() -> dict[str, sp.Matrix]:
    """The pose in mahilab's {0} (= base_link) of the DH frame each body is fixed to."""
    q1, q2, q3 = _Q
    f1 = _dh(0, 0, 0, q1)
    chain1_2 = f1 * _dh(0, sp.pi / 2, 0, q2)
    chain1_3 = chain1_2 * _dh(L1, 0, 0, q3 - q2)
    chain2_2 = f1 * _dh(0, sp.pi / 2, 0, q3 - sp.pi / 2)
    chain2_3 = chain2_2 * _dh(L3, 0, 0, q2 - q3)
    return {"g": f1, "be": chain1_2, "a": chain1_3, "df": chain2_2, "c": chain2_3}


def _lagrangian() -> tuple[sp.Matrix, sp.Matrix]:
    """(M, N): mass matrix (with the rotor armature) and gravity torque, symbolic in q."""
    q, qd = sp.Matrix(_Q), sp.Matrix(_QD)
    kinetic, potential = sp.Integer(0), sp.Integer(0)
    for name, pose in _frames().items():
        mass, pc, (xx, xy, xz, yy, yz, zz) = BODIES[name]
        inertia = sp.Matrix([[xx, -xy, -xz], [-xy, yy, -yz], [-xz, -yz, zz]])
        rotation, origin = pose[:3, :3], pose[:3, 3]
        com = origin + rotation * sp.Matrix(pc)                    # in {0}
        v = com.jacobian(q) * qd                                   # true COM velocity
        rotation_rate = sum((rotation.diff(qi) * qdi for qi, qdi in zip(_Q, _QD)), sp.zeros(3, 3))
        w_hat = rotation.T * rotation_rate                         # body-frame omega^, skew
        w = sp.Matrix([w_hat[2, 1], w_hat[0, 2], w_hat[1, 0]])
        kinetic += mass * (v.T * v)[0] / 2 + (w.T * inertia * w)[0] / 2
        potential += mass * GRAVITY * com[2]                       # gravity along -z of {0}
    m = sp.hessian(kinetic, qd)                                    # T = 1/2 qd^T M qd
    m += sp.diag(*[J_MOT * eta**2 for eta in ETA])                 # reflected rotor inertia
    n = sp.Matrix([potential.diff(qi) for qi in _Q])
    return m, n


@functools.cache
def _lambdified() -> tuple:
    """(mass matrix, gravity) as NumPy functions of q1..q3, derived on the first call (a second
    of SymPy that a test process importing this module without using it does not pay)."""
    m, n = _lagrangian()
    return sp.lambdify(_Q, m, modules="numpy", cse=True), sp.lambdify(_Q, n, modules="numpy", cse=True)


def mass_matrix(theta) -> np.ndarray:
    """Joint-space mass matrix (kg m^2) at theta = (theta1, theta2, theta3) (rad), rotors included."""
    t = np.asarray(theta, dtype=float).reshape(3)
    return np.array(_lambdified()[0](*t), dtype=float).reshape(3, 3)


def gravity(theta) -> np.ndarray:
    """Gravity torque dV/dtheta (N m) at theta (rad)."""
    t = np.asarray(theta, dtype=float).reshape(3)
    return np.array(_lambdified()[1](*t), dtype=float).reshape(3)


# --- self-check (run: python tests/references/cad.py) ------------------------------------------
# A second, purely numeric model, of OUR links (robots/phantom_description/config/premium_1_5_cad,
# physical_parameters.yaml, kinematics.yaml and actuation.yaml), in OUR link frames: M = sum over
# links of m Jv^T Jv + Jw^T R I R^T Jw, N = -sum m g^T Jv, with analytic Jacobians of each
# link's COM. It reads the YAML only to be compared with; the reference above never does.

def _numeric_model(folder):
    from pathlib import Path

    import yaml

    folder = Path(folder)
    phys = yaml.safe_load((folder / "physical_parameters.yaml").read_text())
    kin = yaml.safe_load((folder / "kinematics.yaml").read_text())
    act = yaml.safe_load((folder / "actuation.yaml").read_text())
    l1, l3, g = kin["l1"], kin["l3"], phys["gravity"]
    armature = np.diag([act["motor"]["rotor_inertia"] * act["transmission_ratio"][j] ** 2
                        for j in ("joint1", "joint2", "joint3")])
    links = {}
    for name, link in phys["links"].items():
        i = link["inertia"]
        links[name] = (link["mass"], np.array(link["com"], dtype=float),
                       np.array([[i["xx"], i["xy"], i["xz"]], [i["xy"], i["yy"], i["yz"]],
                                 [i["xz"], i["yz"], i["zz"]]]))
    # link: (which joint turns it in the vertical plane: 0 none, 1 theta2, 2 theta3)
    turns = {"turret_link": 0, "upper_arm_link": 1, "crank_link": 2, "lower_bar_link": 1, "forearm_link": 2}
    axis = np.array([0.0, -1.0, 0.0])                              # joints 2, 3 in the turret

    def ry(angle):                                                  # rotation about -y by angle
        c, s = np.cos(angle), np.sin(angle)
        return np.array([[c, 0, -s], [0, 1, 0], [s, 0, c]])

    def evaluate(theta):
        t1, t2, t3 = theta
        c1, s1 = np.cos(t1), np.sin(t1)
        rz = np.array([[c1, -s1, 0], [s1, c1, 0], [0, 0, 1]])
        pin = np.array([l3 * np.sin(t3), 0, -l3 * np.cos(t3)])      # crank pin, turret frame
        d_pin = np.array([l3 * np.cos(t3), 0, l3 * np.sin(t3)])     # d pin / d theta3
        bar_end = pin + l1 * np.array([np.cos(t2), 0, np.sin(t2)])  # forearm hinge
        d_bar_end = l1 * np.array([-np.sin(t2), 0, np.cos(t2)])     # d bar_end / d theta2
        origins = {"turret_link": (np.zeros(3), np.zeros(3), np.zeros(3)),
                   "upper_arm_link": (np.zeros(3), np.zeros(3), np.zeros(3)),
                   "crank_link": (np.zeros(3), np.zeros(3), np.zeros(3)),
                   "lower_bar_link": (pin, np.zeros(3), d_pin),
                   "forearm_link": (bar_end, d_bar_end, d_pin)}     # (origin, d/dtheta2, d/dtheta3)
        m_total, n_total = armature.copy(), np.zeros(3)
        for name, (mass, com, inertia) in links.items():
            k = turns[name]
            plane = ry((0.0, t2, t3)[k])
            origin, do2, do3 = origins[name]
            r_com = plane @ com                                     # COM from the origin, turret axes
            p = origin + r_com                                      # COM in the turret frame
            dp = [np.cross([0, 0, 1.0], p), do2.copy(), do3.copy()]
            if k:
                dp[k] += np.cross(axis, r_com)                      # the link's own rotation
            jv = rz @ np.column_stack(dp)
            jw = np.column_stack([[0, 0, 1.0], rz @ axis if k == 1 else np.zeros(3),
                                  rz @ axis if k == 2 else np.zeros(3)])
            rot = rz @ plane
            m_total += mass * jv.T @ jv + jw.T @ rot @ inertia @ rot.T @ jw
            n_total += mass * g * jv[2]                             # dV/dtheta, V = m g z
        return m_total, n_total

    return evaluate


def _self_check(n: int = 200, seed: int = 20261122) -> tuple[float, float]:
    from pathlib import Path

    import yaml

    folder = Path(__file__).resolve().parent.parent / "robots/phantom_description/config/premium_1_5_cad"
    model = _numeric_model(folder)
    lim = yaml.safe_load((folder / "joint_limits.yaml").read_text())
    lower = np.array([lim[j]["lower"] for j in ("joint1", "joint2", "joint3")])
    upper = np.array([lim[j]["upper"] for j in ("joint1", "joint2", "joint3")])
    rng, thetas = np.random.default_rng(seed), []
    while len(thetas) < n:
        t = rng.uniform(lower, upper)
        if (t[1] - t[2] <= lim["stops"]["theta2_minus_theta3_max"]
                and t[2] - t[1] <= lim["stops"]["theta3_minus_theta2_max"]):
            thetas.append(t)
    ref_m = np.array([mass_matrix(t) for t in thetas])
    ref_n = np.array([gravity(t) for t in thetas])
    num = [model(t) for t in thetas]
    num_m, num_n = np.array([x[0] for x in num]), np.array([x[1] for x in num])
    return (float(np.abs(num_m - ref_m).max() / np.abs(ref_m).max()),
            float(np.abs(num_n - ref_n).max() / np.abs(ref_n).max()))


if __name__ == "__main__":
    err_m, err_n = _self_check()
    print(f"200 states inside the stops: mass matrix relative error {err_m:.2e}, gravity {err_n:.2e}")
    assert err_m < 1e-9 and err_n < 1e-9
