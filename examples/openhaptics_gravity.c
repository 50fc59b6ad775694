/* Gravity compensation in OpenHaptics' own servo loop: an HDAPI program in the shape of
 * OpenHaptics' samples (hdInitDevice, hdScheduleAsynchronous, hdStartScheduler, a callback
 * between hdBeginFrame and hdEndFrame), with the three lines of docs/servo-loop.md added.
 *
 * Against a real device: gcc -I $OH/include examples/openhaptics_gravity.c -L $OH/lib -lHD -lm
 *   -I robots/phantom_description/include -DPHANTOM_HEADER='"touch.h"'
 * Without one: phantom-pin --model touch openhaptics-sim build sim, then the same with
 *   -I sim/include -L sim/lib, and run with LD_LIBRARY_PATH=sim/lib (tests/interfaces/openhaptics/test_stand_in.py).
 *
 * ./openhaptics_gravity [SECONDS] runs the loop that long (default 5) and prints the stylus's
 * start and end positions (mm, HD_CURRENT_POSITION). -DJOINT_TORQUE sends the compensation as
 * HD_CURRENT_JOINT_TORQUE (mN m) instead of HD_CURRENT_FORCE (N); -DWITHOUT_COMPENSATION leaves
 * the three lines out (the stylus then falls). */
#include <stdio.h>
#include <stdlib.h>

#include <HD/hd.h>

#ifndef PHANTOM_HEADER
#define PHANTOM_HEADER "premium_1_5.h"
#endif
#include PHANTOM_HEADER

typedef struct {
    long ticks, duration;          /* servo ticks run, and to run (1 kHz) */
    double start[3], end[3];       /* mm */
} Run;

static HDCallbackCode HDCALLBACK servo(void *data)
{
    Run *run = (Run *)data;
    HDErrorInfo error;
    double a[3], g[3] = {0.0, 0.0, 0.0}, out[3], p[3];
    HHD device = hdGetCurrentDevice();
    (void)a; (void)g; (void)out;

    hdBeginFrame(device);
    hdGetDoublev(HD_CURRENT_POSITION, p);
#ifndef WITHOUT_COMPENSATION
    /* the three lines (docs/servo-loop.md): */
    hdGetDoublev(HD_CURRENT_JOINT_ANGLES, a);  if (PHANTOM_STYLUS) hdGetDoublev(HD_CURRENT_GIMBAL_ANGLES, g);
#ifdef JOINT_TORQUE
    phantom_openhaptics_joint_torque(a, g, out);  hdSetDoublev(HD_CURRENT_JOINT_TORQUE, out);
#else
    phantom_openhaptics_force(a, g, out);  hdSetDoublev(HD_CURRENT_FORCE, out);
#endif
#endif
    hdEndFrame(device);

    if (run->ticks == 0) {
        run->start[0] = p[0]; run->start[1] = p[1]; run->start[2] = p[2];
    }
    run->end[0] = p[0]; run->end[1] = p[1]; run->end[2] = p[2];
    if (HD_DEVICE_ERROR(error = hdGetError())) {
        fprintf(stderr, "servo callback: %s\n", hdGetErrorString(error.errorCode));
        return HD_CALLBACK_DONE;
    }
    return ++run->ticks < run->duration ? HD_CALLBACK_CONTINUE : HD_CALLBACK_DONE;
}

int main(int argc, char *argv[])
{
    HDErrorInfo error;
    HDSchedulerHandle handle;
    Run run = {0, 5000, {0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}};
    HHD device = hdInitDevice(HD_DEFAULT_DEVICE);

    if (HD_DEVICE_ERROR(error = hdGetError())) {
        fprintf(stderr, "hdInitDevice: %s\n", hdGetErrorString(error.errorCode));
        return 1;
    }
    if (argc > 1)
        run.duration = (long)(1000.0 * atof(argv[1]));
    printf("device: %s\n", hdGetString(HD_DEVICE_MODEL_TYPE));
    handle = hdScheduleAsynchronous(servo, &run, HD_MAX_SCHEDULER_PRIORITY);
    hdEnable(HD_FORCE_OUTPUT);
    hdStartScheduler();
    if (HD_DEVICE_ERROR(error = hdGetError())) {
        fprintf(stderr, "hdStartScheduler: %s\n", hdGetErrorString(error.errorCode));
        return 1;
    }
    hdWaitForCompletion(handle, HD_WAIT_INFINITE);
    hdStopScheduler();
    hdDisableDevice(device);
    printf("ticks: %ld\nstart: %.6f %.6f %.6f\nend: %.6f %.6f %.6f\n", run.ticks, run.start[0], run.start[1],
           run.start[2], run.end[0], run.end[1], run.end[2]);
    return 0;
}
