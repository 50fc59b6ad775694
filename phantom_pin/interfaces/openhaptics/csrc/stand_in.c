/* phantom_pin's stand-in for OpenHaptics' libHD: the HDAPI subset that pyOpenHaptics and the
 * public drivers call, over phantom_pin's simulated device.
 *
 * hdInitDevice starts the device (python -m phantom_pin.interfaces.openhaptics.plant, over a
 * socket pair on its standard input and output: phantom_pin/interfaces/openhaptics/plant.py
 * says what crosses it). hdStartScheduler starts the servo thread: every tick (1 ms at the
 * default rate) it runs the scheduled callbacks, highest priority first, in the state of that
 * tick; then it sends the force and joint torque of the tick's last frame (hdEndFrame) to the
 * device, which holds them over the next period and answers the next tick's state. So a force
 * computed from a tick's angles acts in that same tick. Ticks are paced to the monotonic clock
 * (PHANTOM_PIN_HD_REALTIME=0: as fast as the device steps, for tests).
 *
 * Errors are OpenHaptics' codes on an error stack that hdGetError pops, most recent first; the
 * stand-in never integrates a non-finite command, never exits or aborts the host, and reports a
 * device that died as HD_DEVICE_FAULT. Built by phantom_pin.interfaces.openhaptics.stand_in
 * (gcc -shared -fPIC; layout.h is written there, from plant.py's constants). */
#define _GNU_SOURCE
#include <HD/hd.h>
#include <HD/phantom_pin_sim.h>

#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "layout.h"

extern char **environ;

#define MAX_OPS 64
#define MAX_ERRORS 64

typedef struct {
    HDSchedulerHandle handle;
    HDSchedulerCallback function;
    void *data;
    HDushort priority;
    unsigned long order;
    int active;
    int synchronous;
} Operation;

/* g_lock guards everything below; callbacks run without it. */
static pthread_mutex_t g_lock = PTHREAD_MUTEX_INITIALIZER;
static pthread_cond_t g_changed = PTHREAD_COND_INITIALIZER;

static int g_initialized, g_socket = -1;
static pid_t g_pid;
static const HHD g_handle = 0;
static double g_info[PP_INFO];
static char g_model_type[128];
static double g_current[PP_STATE], g_last[PP_STATE];
static HDint g_buttons, g_last_buttons, g_next_buttons;
static double g_hand[3];
static int g_enabled[5];                 /* HD_FORCE_OUTPUT .. HD_ONE_FRAME_LIMIT */
static int g_in_frame;
static double g_frame_force[3], g_frame_torque[3];     /* set in the open frame */
static double g_tick_force[3], g_tick_torque[3];       /* of the tick's last ended frame */
static double g_last_force[3], g_last_torque[3];       /* sent at the previous tick */
static int g_tick_framed;                              /* a frame ended in this tick */
static HDErrorInfo g_errors[MAX_ERRORS];
static int g_error_count;

static Operation g_ops[MAX_OPS];
static int g_op_count;
static HDSchedulerHandle g_next_handle = 1;
static unsigned long g_next_order;
static pthread_t g_thread;
static int g_running, g_stop;
static unsigned long g_rate = 1000;
static HDulong g_ticks;
static struct timespec g_tick_start;
static __thread int t_scheduler;         /* this thread is the servo thread */

static void push_error(HDerror code, int internal)
{
    /* with g_lock held */
    if (g_error_count == MAX_ERRORS) {   /* the oldest is dropped */
        memmove(g_errors, g_errors + 1, (MAX_ERRORS - 1) * sizeof(HDErrorInfo));
        --g_error_count;
    }
    g_errors[g_error_count].errorCode = code;
    g_errors[g_error_count].internalErrorCode = internal;
    g_errors[g_error_count].hHD = g_handle;
    ++g_error_count;
}

static void error_now(HDerror code)
{
    pthread_mutex_lock(&g_lock);
    push_error(code, 0);
    pthread_mutex_unlock(&g_lock);
}

static int finite3(const double v[3])
{
    return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]);
}

/* -- the device process ------------------------------------------------------------------ */

static int write_all(int fd, const void *data, size_t size)
{
    const char *p = data;
    while (size) {
        ssize_t n = send(fd, p, size, MSG_NOSIGNAL);
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0)
            return -1;
        p += n;
        size -= (size_t)n;
    }
    return 0;
}

static int read_all(int fd, void *data, size_t size)
{
    char *p = data;
    while (size) {
        ssize_t n = recv(fd, p, size, 0);
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0)
            return -1;
        p += n;
        size -= (size_t)n;
    }
    return 0;
}

static void stop_device(void)
{
    /* with g_lock held or the scheduler stopped */
    if (g_socket >= 0) {
        double quit[PP_COMMAND] = {PP_QUIT};
        write_all(g_socket, quit, sizeof quit);
        close(g_socket);
        g_socket = -1;
        waitpid(g_pid, NULL, 0);
    }
}

/* Starts the device and reads its ready line and first state: 0, or -1 with a message printed. */
static int start_device(void)
{
    int pair[2];
    const char *python = getenv("PHANTOM_PIN_HD_PYTHON");
    char *argv[] = {NULL, "-m", "phantom_pin.interfaces.openhaptics.plant", NULL};
    char **env;
    char model[256], line[4096];
    size_t count = 0, i, used = 0;
    posix_spawn_file_actions_t actions;
    int status;

    argv[0] = (char *)(python && *python ? python : PP_PYTHON);
    if (socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, pair) != 0) {
        fprintf(stderr, "phantom_pin stand-in: socketpair: %s\n", strerror(errno));
        return -1;
    }
    while (environ[count])
        ++count;
    env = calloc(count + 2, sizeof(char *));
    if (!env) {
        close(pair[0]);
        close(pair[1]);
        return -1;
    }
    for (i = 0; i < count; ++i)
        env[i] = environ[i];
    if (!getenv("PHANTOM_PIN_HD_MODEL")) {   /* the model the library was built for */
        snprintf(model, sizeof model, "PHANTOM_PIN_HD_MODEL=%s", PP_MODEL);
        env[count++] = model;
    }
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, pair[1], 0);
    posix_spawn_file_actions_adddup2(&actions, pair[1], 1);
    status = posix_spawn(&g_pid, argv[0], &actions, NULL, argv, env);
    posix_spawn_file_actions_destroy(&actions);
    free(env);
    close(pair[1]);
    if (status != 0) {
        fprintf(stderr, "phantom_pin stand-in: cannot start %s: %s\n", argv[0], strerror(status));
        close(pair[0]);
        return -1;
    }
    g_socket = pair[0];
    while (used + 1 < sizeof line) {        /* the text line, a byte at a time (once) */
        if (read_all(g_socket, line + used, 1) != 0)
            break;
        if (line[used++] == '\n')
            break;
    }
    line[used] = '\0';
    if (strncmp(line, "ready ", 6) != 0) {
        fprintf(stderr, "phantom_pin stand-in: the simulated device did not start: %s%s", used ? line : "no answer\n",
                used && line[used - 1] != '\n' ? "\n" : "");
        stop_device();
        return -1;
    }
    {
        char *p = line + 6, *end;
        for (i = 0; i < PP_INFO; ++i) {
            g_info[i] = strtod(p, &end);
            p = end;
        }
        while (*p == ' ')
            ++p;
        snprintf(g_model_type, sizeof g_model_type, "%s", p);
        g_model_type[strcspn(g_model_type, "\n")] = '\0';
    }
    if (read_all(g_socket, g_current, sizeof g_current) != 0) {
        fprintf(stderr, "phantom_pin stand-in: the simulated device sent no state\n");
        stop_device();
        return -1;
    }
    memcpy(g_last, g_current, sizeof g_last);
    return 0;
}

/* -- the device ------------------------------------------------------------------------------ */

HDAPI HHD HDAPIENTRY hdInitDevice(HDstring pConfigName)
{
    (void)pConfigName;    /* any name: the one simulated device */
    pthread_mutex_lock(&g_lock);
    if (g_initialized) {
        push_error(HD_DEVICE_ALREADY_INITIATED, 0);
        pthread_mutex_unlock(&g_lock);
        return HD_INVALID_HANDLE;
    }
    if (start_device() != 0) {
        push_error(HD_DEVICE_FAULT, 0);
        pthread_mutex_unlock(&g_lock);
        return HD_INVALID_HANDLE;
    }
    g_initialized = 1;
    g_in_frame = 0;
    memset(g_enabled, 0, sizeof g_enabled);
    g_enabled[HD_MAX_FORCE_CLAMPING - HD_FORCE_OUTPUT] = 1;
    pthread_mutex_unlock(&g_lock);
    return g_handle;
}

static int check_handle(HHD hHD)
{
    /* with g_lock held: 1 if hHD is the initialized device, else an error pushed */
    if (!g_initialized || hHD != g_handle) {
        push_error(HD_BAD_HANDLE, 0);
        return 0;
    }
    return 1;
}

HDAPI void HDAPIENTRY hdMakeCurrentDevice(HHD hHD)
{
    pthread_mutex_lock(&g_lock);
    check_handle(hHD);
    pthread_mutex_unlock(&g_lock);
}

HDAPI HHD HDAPIENTRY hdGetCurrentDevice(void)
{
    HHD out;
    pthread_mutex_lock(&g_lock);
    out = g_initialized ? g_handle : HD_INVALID_HANDLE;
    if (!g_initialized)
        push_error(HD_BAD_HANDLE, 0);
    pthread_mutex_unlock(&g_lock);
    return out;
}

HDAPI void HDAPIENTRY hdDisableDevice(HHD hHD)
{
    int running;
    pthread_mutex_lock(&g_lock);
    if (!check_handle(hHD)) {
        pthread_mutex_unlock(&g_lock);
        return;
    }
    running = g_running;
    pthread_mutex_unlock(&g_lock);
    if (running)
        hdStopScheduler();
    pthread_mutex_lock(&g_lock);
    stop_device();
    g_initialized = 0;
    pthread_mutex_unlock(&g_lock);
}

HDAPI void HDAPIENTRY hdBeginFrame(HHD hHD)
{
    pthread_mutex_lock(&g_lock);
    if (check_handle(hHD)) {
        if (g_in_frame) {
            push_error(HD_ILLEGAL_BEGIN, 0);
        } else {
            g_in_frame = 1;      /* a frame starts with no force: what it does not set is zero */
            memset(g_frame_force, 0, sizeof g_frame_force);
            memset(g_frame_torque, 0, sizeof g_frame_torque);
        }
    }
    pthread_mutex_unlock(&g_lock);
}

HDAPI void HDAPIENTRY hdEndFrame(HHD hHD)
{
    pthread_mutex_lock(&g_lock);
    if (check_handle(hHD)) {
        if (!g_in_frame) {
            push_error(HD_ILLEGAL_END, 0);
        } else {
            g_in_frame = 0;
            memcpy(g_tick_force, g_frame_force, sizeof g_tick_force);
            memcpy(g_tick_torque, g_frame_torque, sizeof g_tick_torque);
            g_tick_framed = 1;
        }
    }
    pthread_mutex_unlock(&g_lock);
}

HDAPI HDErrorInfo HDAPIENTRY hdGetError(void)
{
    HDErrorInfo out = {HD_SUCCESS, 0, g_handle};
    pthread_mutex_lock(&g_lock);
    if (g_error_count)
        out = g_errors[--g_error_count];
    pthread_mutex_unlock(&g_lock);
    return out;
}

HDAPI HDstring HDAPIENTRY hdGetErrorString(HDerror errorCode)
{
    switch (errorCode) {
    case HD_SUCCESS: return "HD_SUCCESS: no error";
    case HD_INVALID_ENUM: return "HD_INVALID_ENUM: not a parameter or capability of this device";
    case HD_INVALID_VALUE: return "HD_INVALID_VALUE: a value out of range, non-finite or missing";
    case HD_INVALID_OPERATION: return "HD_INVALID_OPERATION: not allowed now";
    case HD_INVALID_INPUT_TYPE: return "HD_INVALID_INPUT_TYPE: the parameter does not take that type";
    case HD_BAD_HANDLE: return "HD_BAD_HANDLE: no such initialized device";
    case HD_WARM_MOTORS: return "HD_WARM_MOTORS";
    case HD_EXCEEDED_MAX_FORCE: return "HD_EXCEEDED_MAX_FORCE: the command was clamped to the nominal maximum";
    case HD_EXCEEDED_MAX_FORCE_IMPULSE: return "HD_EXCEEDED_MAX_FORCE_IMPULSE";
    case HD_EXCEEDED_MAX_VELOCITY: return "HD_EXCEEDED_MAX_VELOCITY";
    case HD_FORCE_ERROR: return "HD_FORCE_ERROR";
    case HD_DEVICE_FAULT: return "HD_DEVICE_FAULT: the simulated device failed or did not start";
    case HD_DEVICE_ALREADY_INITIATED: return "HD_DEVICE_ALREADY_INITIATED";
    case HD_COMM_ERROR: return "HD_COMM_ERROR";
    case HD_COMM_CONFIG_ERROR: return "HD_COMM_CONFIG_ERROR";
    case HD_TIMER_ERROR: return "HD_TIMER_ERROR";
    case HD_ILLEGAL_BEGIN: return "HD_ILLEGAL_BEGIN: a frame begun inside a frame";
    case HD_ILLEGAL_END: return "HD_ILLEGAL_END: a frame ended that was not begun";
    case HD_FRAME_ERROR: return "HD_FRAME_ERROR";
    case HD_INVALID_PRIORITY: return "HD_INVALID_PRIORITY";
    case HD_SCHEDULER_FULL: return "HD_SCHEDULER_FULL: too many scheduled callbacks";
    case HD_INVALID_LICENSE: return "HD_INVALID_LICENSE";
    default: return "unknown HD error code";
    }
}

/* -- capabilities ---------------------------------------------------------------------------- */

static int capability(HDenum cap)
{
    if (cap < HD_FORCE_OUTPUT || cap > HD_ONE_FRAME_LIMIT) {
        push_error(HD_INVALID_ENUM, 0);
        return -1;
    }
    return (int)(cap - HD_FORCE_OUTPUT);
}

static void set_capability(HDenum cap, int value)
{
    int i;
    pthread_mutex_lock(&g_lock);
    if ((i = capability(cap)) >= 0)
        g_enabled[i] = value;
    pthread_mutex_unlock(&g_lock);
}

HDAPI void HDAPIENTRY hdEnable(HDenum cap) { set_capability(cap, 1); }
HDAPI void HDAPIENTRY hdDisable(HDenum cap) { set_capability(cap, 0); }

HDAPI HDboolean HDAPIENTRY hdIsEnabled(HDenum cap)
{
    int i;
    HDboolean out = HD_FALSE;
    pthread_mutex_lock(&g_lock);
    if ((i = capability(cap)) >= 0)
        out = g_enabled[i] ? HD_TRUE : HD_FALSE;
    pthread_mutex_unlock(&g_lock);
    return out;
}

/* -- hdGet ----------------------------------------------------------------------------------- */

/* The numbers of a parameter (with g_lock held): their count (0 and an error pushed for a
 * parameter this device does not have), and whether they are integers (*integer). */
static int parameter(HDenum pname, double out[16], int *integer)
{
    const double *state = g_current;
    int i;
    *integer = 0;
    switch (pname) {        /* the previous tick's state: the current parameter of g_last */
    case HD_LAST_POSITION: state = g_last; pname = HD_CURRENT_POSITION; break;
    case HD_LAST_VELOCITY: state = g_last; pname = HD_CURRENT_VELOCITY; break;
    case HD_LAST_TRANSFORM: state = g_last; pname = HD_CURRENT_TRANSFORM; break;
    case HD_LAST_JOINT_ANGLES: state = g_last; pname = HD_CURRENT_JOINT_ANGLES; break;
    case HD_LAST_GIMBAL_ANGLES: state = g_last; pname = HD_CURRENT_GIMBAL_ANGLES; break;
    default: break;
    }
    switch (pname) {
    case HD_CURRENT_JOINT_ANGLES: memcpy(out, state + PP_JOINT, 3 * sizeof(double)); return 3;
    case HD_CURRENT_GIMBAL_ANGLES:
        if (!g_info[PP_HAS_GIMBAL]) {
            push_error(HD_INVALID_ENUM, 0);     /* no stylus gimbal on this model */
            return 0;
        }
        memcpy(out, state + PP_GIMBAL, 3 * sizeof(double));
        return 3;
    case HD_CURRENT_POSITION: memcpy(out, state + PP_POSITION, 3 * sizeof(double)); return 3;
    case HD_CURRENT_VELOCITY: memcpy(out, state + PP_VELOCITY, 3 * sizeof(double)); return 3;
    case HD_CURRENT_TRANSFORM: memcpy(out, state + PP_TRANSFORM, 16 * sizeof(double)); return 16;
    case HD_CURRENT_FORCE: memcpy(out, g_in_frame ? g_frame_force : g_tick_force, 3 * sizeof(double)); return 3;
    case HD_CURRENT_JOINT_TORQUE: memcpy(out, g_in_frame ? g_frame_torque : g_tick_torque, 3 * sizeof(double)); return 3;
    case HD_LAST_FORCE: memcpy(out, g_last_force, 3 * sizeof(double)); return 3;
    case HD_LAST_JOINT_TORQUE: memcpy(out, g_last_torque, 3 * sizeof(double)); return 3;
    case HD_NOMINAL_MAX_FORCE: out[0] = g_info[PP_MAX_FORCE]; return 1;
    case HD_NOMINAL_MAX_CONTINUOUS_FORCE: out[0] = g_info[PP_MAX_CONTINUOUS_FORCE]; return 1;
    case HD_NOMINAL_MAX_STIFFNESS: out[0] = g_info[PP_MAX_STIFFNESS]; return 1;
    case HD_MAX_WORKSPACE_DIMENSIONS: case HD_USABLE_WORKSPACE_DIMENSIONS:
        for (i = 0; i < 6; ++i)
            out[i] = g_info[PP_WORKSPACE + i];
        return 6;
    }
    *integer = 1;
    switch (pname) {
    case HD_CURRENT_BUTTONS: out[0] = g_buttons; return 1;
    case HD_LAST_BUTTONS: out[0] = g_last_buttons; return 1;
    case HD_CURRENT_SAFETY_SWITCH: case HD_LAST_SAFETY_SWITCH: out[0] = 1; return 1;   /* the device is armed */
    case HD_CURRENT_INKWELL_SWITCH: case HD_LAST_INKWELL_SWITCH: out[0] = 0; return 1;  /* out of its inkwell */
    case HD_INPUT_DOF: out[0] = g_info[PP_HAS_GIMBAL] ? 6 : 3; return 1;
    case HD_OUTPUT_DOF: out[0] = 3; return 1;
    case HD_UPDATE_RATE: case HD_INSTANTANEOUS_UPDATE_RATE: out[0] = (double)g_rate; return 1;
    case HD_CALIBRATION_STYLE: out[0] = HD_CALIBRATION_ENCODER_RESET; return 1;
    }
    push_error(HD_INVALID_ENUM, 0);
    return 0;
}

#define GETTER(NAME, TYPE, INTEGER_ONLY)                                                         \
    HDAPI void HDAPIENTRY NAME(HDenum pname, TYPE *params)                                       \
    {                                                                                            \
        double values[16];                                                                       \
        int n, i, integer;                                                                       \
        pthread_mutex_lock(&g_lock);                                                             \
        if (!g_initialized) {                                                                    \
            push_error(HD_BAD_HANDLE, 0);                                                        \
        } else if (!params) {                                                                    \
            push_error(HD_INVALID_VALUE, 0);                                                     \
        } else if ((n = parameter(pname, values, &integer)) > 0) {                               \
            if ((INTEGER_ONLY) && !integer)                                                      \
                push_error(HD_INVALID_INPUT_TYPE, 0);                                            \
            else                                                                                 \
                for (i = 0; i < n; ++i)                                                          \
                    params[i] = (TYPE)values[i];                                                 \
        }                                                                                        \
        pthread_mutex_unlock(&g_lock);                                                           \
    }

GETTER(hdGetDoublev, HDdouble, 0)
GETTER(hdGetFloatv, HDfloat, 0)
GETTER(hdGetIntegerv, HDint, 1)
GETTER(hdGetLongv, HDlong, 1)
GETTER(hdGetBooleanv, HDboolean, 1)

HDAPI HDstring HDAPIENTRY hdGetString(HDenum pname)
{
    HDstring out = "";
    pthread_mutex_lock(&g_lock);
    if (!g_initialized)
        push_error(HD_BAD_HANDLE, 0);
    else if (pname == HD_DEVICE_MODEL_TYPE)
        out = g_model_type;
    else if (pname == HD_DEVICE_VENDOR)
        out = "phantom_pin (simulated device)";
    else if (pname == HD_DEVICE_DRIVER_VERSION)
        out = "phantom_pin stand-in for libHD";
    else if (pname == HD_DEVICE_SERIAL_NUMBER)
        out = "SIMULATED";
    else
        push_error(HD_INVALID_ENUM, 0);
    pthread_mutex_unlock(&g_lock);
    return out;
}

/* -- hdSet ----------------------------------------------------------------------------------- */

static void set_command(HDenum pname, const double v[3])
{
    /* with g_lock held */
    double value[3], norm, scale;
    int i, clamped = 0;
    if (pname == HD_CURRENT_GIMBAL_TORQUE || pname == HD_CURRENT_TORQUE || pname == HD_CURRENT_MOTOR_DAC_VALUES) {
        push_error(HD_INVALID_ENUM, 0);      /* no gimbal motors, no torque output on this device */
        return;
    }
    if (pname != HD_CURRENT_FORCE && pname != HD_CURRENT_JOINT_TORQUE) {
        push_error(HD_INVALID_ENUM, 0);
        return;
    }
    if (!g_in_frame) {
        push_error(HD_INVALID_OPERATION, 0);  /* commands are set inside a frame */
        return;
    }
    if (!finite3(v)) {
        push_error(HD_INVALID_VALUE, 0);      /* refused: the frame keeps what it had */
        return;
    }
    memcpy(value, v, sizeof value);
    if (pname == HD_CURRENT_FORCE) {
        norm = sqrt(value[0] * value[0] + value[1] * value[1] + value[2] * value[2]);
        if (norm > g_info[PP_MAX_FORCE]) {   /* its direction kept */
            scale = g_info[PP_MAX_FORCE] / norm;
            for (i = 0; i < 3; ++i)
                value[i] *= scale;
            clamped = 1;
        }
        memcpy(g_frame_force, value, sizeof value);
    } else {
        for (i = 0; i < 3; ++i) {
            double peak = g_info[PP_PEAK_TORQUE + i];
            if (fabs(value[i]) > peak) {
                value[i] = value[i] > 0 ? peak : -peak;
                clamped = 1;
            }
        }
        memcpy(g_frame_torque, value, sizeof value);
    }
    if (clamped)
        push_error(HD_EXCEEDED_MAX_FORCE, 0);
}

HDAPI void HDAPIENTRY hdSetDoublev(HDenum pname, const HDdouble *params)
{
    pthread_mutex_lock(&g_lock);
    if (!g_initialized)
        push_error(HD_BAD_HANDLE, 0);
    else if (!params)
        push_error(HD_INVALID_VALUE, 0);
    else
        set_command(pname, params);
    pthread_mutex_unlock(&g_lock);
}

HDAPI void HDAPIENTRY hdSetFloatv(HDenum pname, const HDfloat *params)
{
    double values[3];
    if (!params) {
        hdSetDoublev(pname, NULL);
        return;
    }
    values[0] = params[0];
    values[1] = params[1];
    values[2] = params[2];
    hdSetDoublev(pname, values);
}

/* No parameter of this device is set as an integer, long or boolean. */
HDAPI void HDAPIENTRY hdSetIntegerv(HDenum pname, const HDint *params) { (void)pname; (void)params; error_now(HD_INVALID_INPUT_TYPE); }
HDAPI void HDAPIENTRY hdSetLongv(HDenum pname, const HDlong *params) { (void)pname; (void)params; error_now(HD_INVALID_INPUT_TYPE); }
HDAPI void HDAPIENTRY hdSetBooleanv(HDenum pname, const HDboolean *params) { (void)pname; (void)params; error_now(HD_INVALID_INPUT_TYPE); }

/* No calibration: the simulated encoders are exact from the start. */
HDAPI HDenum HDAPIENTRY hdCheckCalibration(void) { return HD_CALIBRATION_OK; }
HDAPI HDenum HDAPIENTRY hdCheckCalibrationStyle(void) { return HD_CALIBRATION_ENCODER_RESET; }
HDAPI void HDAPIENTRY hdUpdateCalibration(HDenum style) { (void)style; }

/* -- the hand (phantom_pin_sim.h) ---------------------------------------------------------------- */

HDAPI void HDAPIENTRY phantomPinSimSetHandForce(const HDdouble force[3])
{
    pthread_mutex_lock(&g_lock);
    if (!force || !finite3(force))
        push_error(HD_INVALID_VALUE, 0);
    else
        memcpy(g_hand, force, sizeof g_hand);
    pthread_mutex_unlock(&g_lock);
}

HDAPI void HDAPIENTRY phantomPinSimSetButtons(HDint buttons)
{
    pthread_mutex_lock(&g_lock);
    g_next_buttons = buttons;
    pthread_mutex_unlock(&g_lock);
}

HDAPI HDulong HDAPIENTRY phantomPinSimTicks(void)
{
    HDulong out;
    pthread_mutex_lock(&g_lock);
    out = g_ticks;
    pthread_mutex_unlock(&g_lock);
    return out;
}

/* -- the scheduler --------------------------------------------------------------------------- */

static double seconds(const struct timespec *t) { return (double)t->tv_sec + 1e-9 * (double)t->tv_nsec; }

/* One tick's callbacks, highest priority first (then in the order scheduled). */
static void run_callbacks(void)
{
    Operation ready[MAX_OPS];
    int n = 0, i, j;
    pthread_mutex_lock(&g_lock);
    for (i = 0; i < g_op_count; ++i)
        if (g_ops[i].active)
            ready[n++] = g_ops[i];
    pthread_mutex_unlock(&g_lock);
    for (i = 1; i < n; ++i) {       /* insertion sort: priority down, order up */
        Operation key = ready[i];
        for (j = i - 1; j >= 0 && (ready[j].priority < key.priority ||
                                   (ready[j].priority == key.priority && ready[j].order > key.order)); --j)
            ready[j + 1] = ready[j];
        ready[j + 1] = key;
    }
    for (i = 0; i < n; ++i) {
        HDCallbackCode code;
        int still = 0;
        pthread_mutex_lock(&g_lock);
        for (j = 0; j < g_op_count; ++j)
            if (g_ops[j].handle == ready[i].handle && g_ops[j].active)
                still = 1;
        pthread_mutex_unlock(&g_lock);
        if (!still)                 /* unscheduled by an earlier callback of this tick */
            continue;
        code = ready[i].function(ready[i].data);
        pthread_mutex_lock(&g_lock);
        if (code != HD_CALLBACK_CONTINUE) {
            if (code != HD_CALLBACK_DONE)
                push_error(HD_INVALID_VALUE, (int)code);   /* garbage: taken as done */
            for (j = 0; j < g_op_count; ++j)
                if (g_ops[j].handle == ready[i].handle)
                    g_ops[j].active = 0;
            pthread_cond_broadcast(&g_changed);
        }
        pthread_mutex_unlock(&g_lock);
    }
    pthread_mutex_lock(&g_lock);    /* the finished ones leave the table */
    for (i = j = 0; i < g_op_count; ++i)
        if (g_ops[i].active)
            g_ops[j++] = g_ops[i];
    g_op_count = j;
    if (g_in_frame) {               /* a frame left open: ended, its command dropped */
        g_in_frame = 0;
        push_error(HD_ILLEGAL_END, 0);
    }
    pthread_mutex_unlock(&g_lock);
}

/* Sends the tick's command and reads the next state: 0, or -1 (the device is gone or failed). */
static int exchange(void)
{
    double command[PP_COMMAND], state[PP_STATE];
    int i, socket;
    pthread_mutex_lock(&g_lock);
    command[0] = g_enabled[0] ? PP_ENABLED : PP_DISABLED;
    for (i = 0; i < 3; ++i) {
        command[PP_FORCE + i] = g_tick_force[i];
        command[PP_TORQUE + i] = g_tick_torque[i];
        command[PP_HAND + i] = g_hand[i];
    }
    command[PP_PERIOD] = 1.0 / (double)g_rate;
    command[PP_FRAMED] = g_tick_framed;
    g_tick_framed = 0;
    socket = g_socket;
    pthread_mutex_unlock(&g_lock);
    if (socket < 0 || write_all(socket, command, sizeof command) != 0 || read_all(socket, state, sizeof state) != 0)
        return -1;
    pthread_mutex_lock(&g_lock);
    if (state[PP_STATE - 1] != 0.0 || !finite3(state)) {
        pthread_mutex_unlock(&g_lock);
        return -1;
    }
    memcpy(g_last, g_current, sizeof g_last);
    memcpy(g_current, state, sizeof g_current);
    memcpy(g_last_force, g_tick_force, sizeof g_last_force);
    memcpy(g_last_torque, g_tick_torque, sizeof g_last_torque);
    memset(g_tick_force, 0, sizeof g_tick_force);       /* a tick without a frame sends no force */
    memset(g_tick_torque, 0, sizeof g_tick_torque);
    g_last_buttons = g_buttons;
    g_buttons = g_next_buttons;
    ++g_ticks;
    pthread_mutex_unlock(&g_lock);
    return 0;
}

static void *servo(void *unused)
{
    struct timespec next, now;
    const char *realtime = getenv("PHANTOM_PIN_HD_REALTIME");
    int paced = !(realtime && strcmp(realtime, "0") == 0);
    (void)unused;
    t_scheduler = 1;
    clock_gettime(CLOCK_MONOTONIC, &next);
    for (;;) {
        long period;
        pthread_mutex_lock(&g_lock);
        if (g_stop) {
            pthread_mutex_unlock(&g_lock);
            break;
        }
        clock_gettime(CLOCK_MONOTONIC, &g_tick_start);
        period = (long)(1000000000L / (long)g_rate);
        pthread_mutex_unlock(&g_lock);
        run_callbacks();
        if (exchange() != 0) {
            pthread_mutex_lock(&g_lock);
            push_error(HD_DEVICE_FAULT, 0);
            fprintf(stderr, "phantom_pin stand-in: the simulated device failed; the scheduler stops\n");
            pthread_mutex_unlock(&g_lock);
            break;
        }
        if (paced) {
            next.tv_nsec += period;
            while (next.tv_nsec >= 1000000000L) {
                next.tv_nsec -= 1000000000L;
                ++next.tv_sec;
            }
            clock_gettime(CLOCK_MONOTONIC, &now);
            if (seconds(&now) - seconds(&next) > 0.05)   /* 50 ms behind: start afresh, no burst */
                next = now;
            while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &next, NULL) == EINTR)
                ;
        }
    }
    pthread_mutex_lock(&g_lock);
    g_running = 0;
    for (int i = 0; i < g_op_count; ++i)   /* what is still scheduled does not run again */
        if (g_ops[i].synchronous)
            g_ops[i].active = 0;
    pthread_cond_broadcast(&g_changed);
    pthread_mutex_unlock(&g_lock);
    return NULL;
}

HDAPI void HDAPIENTRY hdStartScheduler(void)
{
    pthread_mutex_lock(&g_lock);
    if (!g_initialized) {
        push_error(HD_BAD_HANDLE, 0);
    } else if (g_running) {
        push_error(HD_INVALID_OPERATION, 0);   /* started twice */
    } else {
        g_stop = 0;
        g_running = 1;
        if (pthread_create(&g_thread, NULL, servo, NULL) != 0) {
            g_running = 0;
            push_error(HD_TIMER_ERROR, 0);
        }
    }
    pthread_mutex_unlock(&g_lock);
}

HDAPI void HDAPIENTRY hdStopScheduler(void)
{
    pthread_t thread;
    pthread_mutex_lock(&g_lock);
    if (!g_running || t_scheduler) {       /* stopped, or asked from a callback: it stops after this tick */
        g_stop = g_running ? 1 : g_stop;
        pthread_mutex_unlock(&g_lock);
        return;
    }
    g_stop = 1;
    thread = g_thread;
    pthread_mutex_unlock(&g_lock);
    pthread_join(thread, NULL);
}

HDAPI void HDAPIENTRY hdSetSchedulerRate(HDulong nRate)
{
    pthread_mutex_lock(&g_lock);
    if (nRate != 500 && nRate != 1000 && nRate != 2000)
        push_error(HD_INVALID_VALUE, 0);      /* OpenHaptics' rates: 500, 1000, 2000 Hz */
    else
        g_rate = nRate;
    pthread_mutex_unlock(&g_lock);
}

static HDSchedulerHandle schedule(HDSchedulerCallback pCallback, void *pUserData, HDushort nPriority, int synchronous)
{
    /* with g_lock held */
    if (!pCallback) {
        push_error(HD_INVALID_VALUE, 0);
        return HD_INVALID_HANDLE;
    }
    if (g_op_count == MAX_OPS) {
        push_error(HD_SCHEDULER_FULL, 0);
        return HD_INVALID_HANDLE;
    }
    g_ops[g_op_count].handle = g_next_handle++;
    g_ops[g_op_count].function = pCallback;
    g_ops[g_op_count].data = pUserData;
    g_ops[g_op_count].priority = nPriority;
    g_ops[g_op_count].order = g_next_order++;
    g_ops[g_op_count].active = 1;
    g_ops[g_op_count].synchronous = synchronous;
    return g_ops[g_op_count++].handle;
}

static int is_active(HDSchedulerHandle h)
{
    int i;
    for (i = 0; i < g_op_count; ++i)
        if (g_ops[i].handle == h && g_ops[i].active)
            return 1;
    return 0;
}

HDAPI HDSchedulerHandle HDAPIENTRY hdScheduleAsynchronous(HDSchedulerCallback pCallback, void *pUserData,
                                                          HDushort nPriority)
{
    HDSchedulerHandle h;
    pthread_mutex_lock(&g_lock);
    h = schedule(pCallback, pUserData, nPriority, 0);
    pthread_mutex_unlock(&g_lock);
    return h;
}

HDAPI void HDAPIENTRY hdScheduleSynchronous(HDSchedulerCallback pCallback, void *pUserData, HDushort nPriority)
{
    HDSchedulerHandle h;
    pthread_mutex_lock(&g_lock);
    if (!pCallback) {
        push_error(HD_INVALID_VALUE, 0);
        pthread_mutex_unlock(&g_lock);
        return;
    }
    if (!g_running || t_scheduler) {      /* no servo thread to wait for: run it here until done */
        pthread_mutex_unlock(&g_lock);
        while (pCallback(pUserData) == HD_CALLBACK_CONTINUE)
            ;
        return;
    }
    h = schedule(pCallback, pUserData, nPriority, 1);
    while (h != HD_INVALID_HANDLE && is_active(h))
        pthread_cond_wait(&g_changed, &g_lock);
    pthread_mutex_unlock(&g_lock);
}

HDAPI void HDAPIENTRY hdUnschedule(HDSchedulerHandle hHandle)
{
    int i, found = 0;
    pthread_mutex_lock(&g_lock);
    for (i = 0; i < g_op_count; ++i)
        if (g_ops[i].handle == hHandle && g_ops[i].active) {
            g_ops[i].active = 0;
            found = 1;
        }
    if (!found)
        push_error(HD_INVALID_OPERATION, 0);
    pthread_cond_broadcast(&g_changed);
    pthread_mutex_unlock(&g_lock);
}

HDAPI HDboolean HDAPIENTRY hdWaitForCompletion(HDSchedulerHandle hHandle, HDWaitCode param)
{
    HDboolean out;
    pthread_mutex_lock(&g_lock);
    if (param == HD_WAIT_INFINITE && !t_scheduler)
        while (g_running && is_active(hHandle))
            pthread_cond_wait(&g_changed, &g_lock);
    else if (param != HD_WAIT_CHECK_STATUS && param != HD_WAIT_INFINITE)
        push_error(HD_INVALID_VALUE, 0);
    out = is_active(hHandle) ? HD_TRUE : HD_FALSE;
    pthread_mutex_unlock(&g_lock);
    return out;
}

HDAPI HDdouble HDAPIENTRY hdGetSchedulerTimeStamp(void)
{
    struct timespec now;
    double out;
    clock_gettime(CLOCK_MONOTONIC, &now);
    pthread_mutex_lock(&g_lock);
    out = seconds(&now) - seconds(&g_tick_start);
    pthread_mutex_unlock(&g_lock);
    return out;
}
