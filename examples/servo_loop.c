/* A 1 kHz servo loop against a generated header (phantom-pin codegen): gravity compensation
 * plus a virtual spring in joint space, tau = N(theta) + K (theta_ref - theta) - B dtheta,
 * closed on a plant written with the same header: M(theta) ddtheta = tau - C(theta, dtheta)
 * dtheta - N(theta), the torque held over each 1 ms period (zero-order hold, as a servo
 * callback's) and integrated by one RK4 step per period (no friction, stops nor saturation:
 * simulate()'s plant with friction=False, hard_stops=False, saturation=False, substeps=1,
 * which tests/codegen/test_generate.py runs against this program's output).
 *
 * Build and run (C99, only the header and <math.h>; the Premium 1.5 by default):
 *     gcc -std=c99 -O2 -I robots/phantom_description/include examples/servo_loop.c -o servo_loop -lm
 *     ./servo_loop            # prints "t theta1 theta2 theta3 tau1 tau2 tau3" per period (s, rad, N m)
 * Another model: -DPHANTOM_HEADER='"touch.h"'. On a device, the controller() below is
 * the whole callback: read theta and dtheta, call it, send tau (docs/servo-loop.md: the three lines). */

#include <stdio.h>

#ifndef PHANTOM_HEADER
#define PHANTOM_HEADER "premium_1_5.h"
#endif
#include PHANTOM_HEADER

#define RATE 1000.0                /* Hz, the servo rate */
#define DURATION 1.0               /* s */
static const double THETA0[3] = {0.0, 0.2, 0.6};      /* rad, start at rest */
static const double THETA_REF[3] = {0.3, 0.5, 0.9};   /* rad, the spring's rest posture */
static const double STIFFNESS = 1.0;                   /* K, N m/rad, each joint */
static const double DAMPING = 0.05;                    /* B, N m s/rad, each joint */

/* The servo callback: gravity compensation plus the virtual spring and damper (N m). */
static void controller(const double theta[3], const double dtheta[3], double tau[3])
{
    int i;
    phantom_gravity(theta, tau);
    for (i = 0; i < 3; ++i)
        tau[i] += STIFFNESS * (THETA_REF[i] - theta[i]) - DAMPING * dtheta[i];
}

/* The plant: ddtheta = M^-1 (tau - C dtheta - N), M symmetric positive definite (Cholesky). */
static void acceleration(const double theta[3], const double dtheta[3], const double tau[3],
                         double ddtheta[3])
{
    double M[9], c[3], n[3], r[3], L[9] = {0}, y[3];
    int i, j, k;
    phantom_mass_matrix(theta, M);
    phantom_coriolis(theta, dtheta, c);
    phantom_gravity(theta, n);
    for (i = 0; i < 3; ++i)
        r[i] = tau[i] - c[i] - n[i];
    for (i = 0; i < 3; ++i)
        for (j = 0; j <= i; ++j) {
            double s = M[3 * i + j];
            for (k = 0; k < j; ++k)
                s -= L[3 * i + k] * L[3 * j + k];
            L[3 * i + j] = (i == j) ? sqrt(s) : s / L[3 * j + j];
        }
    for (i = 0; i < 3; ++i) {
        y[i] = r[i];
        for (k = 0; k < i; ++k)
            y[i] -= L[3 * i + k] * y[k];
        y[i] /= L[3 * i + i];
    }
    for (i = 2; i >= 0; --i) {
        ddtheta[i] = y[i];
        for (k = i + 1; k < 3; ++k)
            ddtheta[i] -= L[3 * k + i] * ddtheta[k];
        ddtheta[i] /= L[3 * i + i];
    }
}

/* One RK4 step of length h of (theta, dtheta) under the held torque tau. */
static void rk4(double theta[3], double dtheta[3], const double tau[3], double h)
{
    double q[3], v[3], kq[4][3], kv[4][3];
    static const double weight[4] = {0.0, 0.5, 0.5, 1.0};
    int s, i;
    for (s = 0; s < 4; ++s) {
        for (i = 0; i < 3; ++i) {
            q[i] = theta[i] + (s ? weight[s] * h * kq[s - 1][i] : 0.0);
            v[i] = dtheta[i] + (s ? weight[s] * h * kv[s - 1][i] : 0.0);
            kq[s][i] = v[i];
        }
        acceleration(q, v, tau, kv[s]);
    }
    for (i = 0; i < 3; ++i) {
        theta[i] += h / 6.0 * (kq[0][i] + 2.0 * kq[1][i] + 2.0 * kq[2][i] + kq[3][i]);
        dtheta[i] += h / 6.0 * (kv[0][i] + 2.0 * kv[1][i] + 2.0 * kv[2][i] + kv[3][i]);
    }
}

int main(void)
{
    double theta[3], dtheta[3] = {0.0, 0.0, 0.0}, tau[3];
    long k, samples = (long)(DURATION * RATE);
    int i;
    for (i = 0; i < 3; ++i)
        theta[i] = THETA0[i];
    for (k = 0; k <= samples; ++k) {
        controller(theta, dtheta, tau);      /* the servo callback, every 1 ms */
        printf("%.17g %.17g %.17g %.17g %.17g %.17g %.17g\n", k / RATE, theta[0], theta[1], theta[2],
               tau[0], tau[1], tau[2]);
        rk4(theta, dtheta, tau, 1.0 / RATE); /* the plant, over the period */
    }
    return 0;
}
