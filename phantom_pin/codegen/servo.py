"""The header's functions in OpenHaptics' terms (phantom_pin.interfaces.conventions' conventions): the angles'
and joint torques' maps, and the compensation that a servo callback sends, HD_CURRENT_FORCE (N)
or HD_CURRENT_JOINT_TORQUE (mN m) of the angles that HD_CURRENT_JOINT_ANGLES and
HD_CURRENT_GIMBAL_ANGLES give, optionally with the friction law at the caller's rates."""

from __future__ import annotations

from phantom_pin.codegen.c import ASSUMES as _ASSUMES
from phantom_pin.codegen.c import function as _function

#: F of J^T F = tau: F = (J^-1)^T tau, J^-1 = adj(J) / det(J) (J row-major, as tip_jacobian's).
_SOLVE = """    double J[9], det;
    {p}_tip_jacobian(theta, J);
    det = J[0] * (J[4] * J[8] - J[5] * J[7]) - J[1] * (J[3] * J[8] - J[5] * J[6]) + J[2] * (J[3] * J[7] - J[4] * J[6]);
    f[0] = (tau[0] * (J[4] * J[8] - J[5] * J[7]) - tau[1] * (J[3] * J[8] - J[5] * J[6])
            + tau[2] * (J[3] * J[7] - J[4] * J[6])) / det;
    f[1] = (-tau[0] * (J[1] * J[8] - J[2] * J[7]) + tau[1] * (J[0] * J[8] - J[2] * J[6])
            - tau[2] * (J[0] * J[7] - J[1] * J[6])) / det;
    f[2] = (tau[0] * (J[1] * J[5] - J[2] * J[4]) - tau[1] * (J[0] * J[5] - J[2] * J[3])
            + tau[2] * (J[0] * J[4] - J[1] * J[3])) / det;"""



def openhaptics(prefix: str, body: dict[str, str], has_gimbal: bool) -> str:
    """OpenHaptics' conventions (phantom_pin.interfaces.conventions): angles theta = (-a1, a2, a3);
    HD_CURRENT_JOINT_TORQUE (mN m) = 1000 (-tau1, tau2, tau3); and the compensation in the servo
    loop's own terms: HD_CURRENT_FORCE (N) or HD_CURRENT_JOINT_TORQUE (mN m) of the angles
    HD_CURRENT_JOINT_ANGLES and HD_CURRENT_GIMBAL_ANGLES give, optionally with friction."""
    p = prefix
    gravity = (f"    {p}_gravity_stylus(theta, gimbal_angles, tau);" if has_gimbal else
               f"    (void)gimbal_angles;\n    {p}_gravity(theta, tau);")
    stylus = ("the stylus gimbal at gimbal_angles (HD_CURRENT_GIMBAL_ANGLES, rad)" if has_gimbal else
              "gimbal_angles ignored (this model has no stylus gimbal: pass NULL)")
    rates = ("joint_rates: the rates of HD_CURRENT_JOINT_ANGLES (rad/s, the caller's estimate, e.g. filtered\n"
             "differences); the friction law in motion of the model is added (viscous and Coulomb, 0 at rest).")
    parts = [
        _function("The report's theta (rad) of OpenHaptics' HD_CURRENT_JOINT_ANGLES (rad): (-a1, a2, a3)\n"
                  "(phantom_pin.interfaces.conventions.theta_from_openhaptics).",
                  f"{p}_theta_from_openhaptics(const double angles[3], double theta[3])",
                  "    theta[0] = -angles[0];\n    theta[1] = angles[1];\n    theta[2] = angles[2];"),
        _function("OpenHaptics joint torques (mN m, for HD_CURRENT_JOINT_TORQUE) of joint torques tau\n"
                  "(N m on theta): 1000 (-tau1, tau2, tau3)\n"
                  "(phantom_pin.interfaces.conventions.openhaptics_torque_from_tau),\n"
                  "each torque acting on its own OpenHaptics angle (SensAble's CommandJointTorque sample\n"
                  "renders a restoring joint spring T = k (0 - a), k > 0, on that reading: docs/servo-loop.md).",
                  f"{p}_openhaptics_torque_from_tau(const double tau[3], double torque[3])",
                  "    torque[0] = -1000.0 * tau[0];\n    torque[1] = 1000.0 * tau[1];\n"
                  "    torque[2] = 1000.0 * tau[2];"),
        _function(f"The friction torques in motion (N m) at joint rates dtheta (rad/s): viscous dtheta +\n"
                  f"Coulomb sign(dtheta) per joint, 0 for a joint at rest (phantom_pin.Device.friction).\n"
                  f"{_ASSUMES}",
                  f"{p}_friction(const double dtheta[3], double tau[3])", body["friction"]),
        _function("The tip force f (N, frame s = OpenHaptics' axes) whose J^T f is tau (N m): J^-T tau, J the\n"
                  "tip Jacobian at theta. At a kinematic singularity (det J = 0: the arm stretched, or the tip\n"
                  "on joint 1's axis) no force gives every torque and the result is not finite.\n"
                  f"{_ASSUMES}",
                  f"{p}_force_from_tau(const double theta[3], const double tau[3], double f[3])",
                  _SOLVE.replace("{p}", p)),
    ]
    if has_gimbal:
        parts.insert(2, _function(
            "Gravity torques (N m on theta) with the stylus gimbal at gimbal (OpenHaptics' raw gimbal angles,\n"
            "rad), as phantom_pin.Phantom.gravity(theta, gimbal=gimbal): the arm's, the gimbal's own held by\n"
            f"the hand. {_ASSUMES}",
            f"{p}_gravity_stylus(const double theta[3], const double gimbal[3], double tau[3])",
            body["gravity_stylus"]))
    for friction in (False, True):
        suffix, arg = ("_friction", ", const double joint_rates[3]") if friction else ("", "")
        extra = (f"\n    {{\n        double rates[3], f[3];\n        {p}_theta_from_openhaptics(joint_rates, rates);\n"
                 f"        {p}_friction(rates, f);\n        tau[0] += f[0];\n        tau[1] += f[1];\n"
                 "        tau[2] += f[2];\n    }") if friction else ""
        more = ("\n" + rates) if friction else ""
        parts.append(_function(
            f"HD_CURRENT_FORCE (N, OpenHaptics' axes) that compensates the device's gravity at the angles\n"
            f"joint_angles (HD_CURRENT_JOINT_ANGLES, rad), {stylus}: J^T F = N(theta).{more}\n"
            f"Between hdBeginFrame and hdEndFrame: hdSetDoublev(HD_CURRENT_FORCE, force). Not finite at a\n"
            f"kinematic singularity ({p}_force_from_tau). {_ASSUMES}",
            f"{p}_openhaptics_force{suffix}(const double joint_angles[3], const double gimbal_angles[3]{arg}, "
            f"double force[3])",
            f"    double theta[3], tau[3];\n    {p}_theta_from_openhaptics(joint_angles, theta);\n{gravity}{extra}\n"
            f"    {p}_force_from_tau(theta, tau, force);"))
        parts.append(_function(
            f"HD_CURRENT_JOINT_TORQUE (mN m on OpenHaptics' angles) that compensates the device's gravity at\n"
            f"joint_angles (HD_CURRENT_JOINT_ANGLES, rad), {stylus}.{more}\n"
            f"Between hdBeginFrame and hdEndFrame: hdSetDoublev(HD_CURRENT_JOINT_TORQUE, torque). {_ASSUMES}",
            f"{p}_openhaptics_joint_torque{suffix}(const double joint_angles[3], const double gimbal_angles[3]{arg}, "
            f"double torque[3])",
            f"    double theta[3], tau[3];\n    {p}_theta_from_openhaptics(joint_angles, theta);\n{gravity}{extra}\n"
            f"    {p}_openhaptics_torque_from_tau(tau, torque);"))
    parts.append(_transparent(p))
    return "\n".join(parts)


#: The estimator and the compensation beyond gravity (phantom_pin.device.estimator and the
#: pyOpenHaptics Compensator's terms, in C): {p} is the prefix.
_TRANSPARENT = """/*
 * The rates (rad/s) and accelerations (rad/s^2) of OpenHaptics' joint angles estimated from one
 * sample a tick, as phantom_pin.device.estimator.Estimator: a first-order low-pass (cutoff Hz)
 * of the backward difference of the angles, then the same of the rate's; zero at the first
 * sample. The caller owns it: {p}_estimator_init once, {p}_estimator_update every tick.
 */
typedef struct {{
    double previous[3], rate[3], acceleration[3];
    double alpha, period;
    int started;
}} {p}_estimator;

static inline void {p}_estimator_init({p}_estimator *e, double rate_hz, double cutoff_hz)
{{
    int i;
    e->period = 1.0 / rate_hz;
    e->alpha = 1.0 - exp(-2.0 * 3.14159265358979323846 * cutoff_hz * e->period);
    e->started = 0;
    for (i = 0; i < 3; ++i)
        e->previous[i] = e->rate[i] = e->acceleration[i] = 0.0;
}}

static inline void {p}_estimator_update({p}_estimator *e, const double angles[3])
{{
    int i;
    for (i = 0; i < 3; ++i) {{
        if (e->started) {{
            double rate = e->rate[i] + e->alpha * ((angles[i] - e->previous[i]) / e->period - e->rate[i]);
            e->acceleration[i] += e->alpha * ((rate - e->rate[i]) / e->period - e->acceleration[i]);
            e->rate[i] = rate;
        }}
        e->previous[i] = angles[i];
    }}
    e->started = 1;
}}

/*
 * HD_CURRENT_JOINT_TORQUE (mN m on OpenHaptics' angles) that compensates gravity, the friction law
 * at the estimated rates (0 for a joint slower than dead_band rad/s), and a share kappa (0 <= kappa
 * < 1) of the inertia, kappa (M(theta) ddtheta + C(theta, dtheta) dtheta), while some joint moves
 * faster than dead_band, as phantom_pin's Compensator(compensate=("gravity", "friction",
 * "inertia")). e: updated with this tick's joint_angles first. The inertia uses the arm's M and C
 * with the stylus at locked_at. Clamp the result to the motors' limits as your loop does.
 * Assumes finite input: no checks, no allocation, no global state.
 */
static inline void {p}_openhaptics_joint_torque_transparent(const double joint_angles[3], const double gimbal_angles[3],
                                                           const {p}_estimator *e, double kappa, double dead_band,
                                                           double torque[3])
{{
    double theta[3], rates[3], accelerations[3], tau[3], f[3], inertia[3], c[3], M[9];
    int i, moving = 0;
    {p}_theta_from_openhaptics(joint_angles, theta);
    {p}_theta_from_openhaptics(e->rate, rates);
    {p}_theta_from_openhaptics(e->acceleration, accelerations);
    {p}_openhaptics_joint_torque(joint_angles, gimbal_angles, torque);
    for (i = 0; i < 3; ++i) {{
        if (fabs(rates[i]) > dead_band)
            moving = 1;
        else
            rates[i] = 0.0;
    }}
    {p}_friction(rates, f);
    for (i = 0; i < 3; ++i)
        tau[i] = f[i];
    if (moving && kappa > 0.0) {{
        {p}_theta_from_openhaptics(e->rate, rates);
        {p}_mass_matrix(theta, M);
        {p}_coriolis(theta, rates, c);
        for (i = 0; i < 3; ++i) {{
            inertia[i] = M[3 * i] * accelerations[0] + M[3 * i + 1] * accelerations[1]
                         + M[3 * i + 2] * accelerations[2];
            tau[i] += kappa * (inertia[i] + c[i]);
        }}
    }}
    {{
        double extra[3];
        {p}_openhaptics_torque_from_tau(tau, extra);
        for (i = 0; i < 3; ++i)
            torque[i] += extra[i];
    }}
}}
"""


def _transparent(prefix: str) -> str:
    """The estimator's type and functions and the transparent joint torque (_TRANSPARENT)."""
    return _TRANSPARENT.format(p=prefix)
