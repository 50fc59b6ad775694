"""The libHD stand-in (phantom_pin.interfaces.openhaptics): an HDAPI program in the shape of
OpenHaptics' samples (examples/openhaptics_gravity.c), built unchanged against it, floats the
stylus with the three lines of docs/servo-loop.md on every model in force and in joint-torque
mode and lets it fall without them; every tick's command satisfies J^T F = gravity against
references independent of Phantom (tests/references/openhaptics.py), in the tick whose state it
was computed from; the headers' values are SensAble's and pyOpenHaptics'; bad calls give
OpenHaptics' error codes and never reach the plant."""

import os
import re
import shutil
import subprocess

import numpy as np
import pytest

from phantom_pin.config import MODELS, models, read
from phantom_pin.interfaces.openhaptics import build, read_record
from phantom_pin.interfaces.openhaptics.stand_in import headers
from references.openhaptics import HDDEFINES, TOLERANCE, falling_posture, framed, residuals, tips

EXAMPLE = MODELS["premium_1_5"].urdf.parents[3] / "examples" / "openhaptics_gravity.c"
INCLUDE = MODELS["premium_1_5"].urdf.parents[1] / "include"
MODES = ("force", "joint_torque")


def header_of(name):
    return {"premium_1_5": "premium_1_5.h", "premium_1_5_cad": "premium_1_5_cad.h", "touch": "touch.h"}[name]


@pytest.fixture(scope="module")
def programs(tmp_path_factory):
    """Per model: its stand-in and the example built against it (force, joint torque, none)."""
    if not shutil.which("gcc"):
        pytest.fail("gcc builds the stand-in: apt-get install gcc (.ci/run installs it)", pytrace=False)
    out = {}
    for name in models():
        folder = tmp_path_factory.mktemp(name)
        build(folder / "sim", name)
        variants = (("force", []), ("joint_torque", ["-DJOINT_TORQUE"]), ("none", ["-DWITHOUT_COMPENSATION"]))
        for variant, flag in variants:
            subprocess.run(["gcc", "-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", *flag,
                            f"-I{folder / 'sim' / 'include'}", f"-I{INCLUDE}", f'-DPHANTOM_HEADER="{header_of(name)}"',
                            str(EXAMPLE), f"-L{folder / 'sim' / 'lib'}", "-lHD", "-lm", "-o", str(folder / variant)],
                           check=True, capture_output=True, text=True)
        out[name] = folder
    return out


def run(folder, variant, seconds, theta, record, **env):
    environment = {**os.environ, "LD_LIBRARY_PATH": str(folder / "sim" / "lib"), "PHANTOM_PIN_HD_REALTIME": "0",
                   "PHANTOM_PIN_HD_THETA0": " ".join(repr(float(t)) for t in theta),
                   "PHANTOM_PIN_HD_RECORD": str(record), **env}
    done = subprocess.run([str(folder / variant), str(seconds)], capture_output=True, text=True, env=environment,
                          timeout=120)
    assert done.returncode == 0, done.stderr
    return read_record(record), done.stdout


@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("name", models())
def test_the_example_floats_the_stylus_with_the_three_lines(programs, name, mode, tmp_path):
    """5 s of the unchanged example with the three lines: the tip (the reference's forward
    kinematics of the recorded theta) stays within 2 mm of where it was let go, and every
    tick's command gives J^T F = gravity (or the joint torques' own) within TOLERANCE."""
    theta0 = falling_posture(name)
    record, _ = run(programs[name], mode, 5, theta0, tmp_path / "record.csv")
    record = framed(record)
    assert len(record["tick"]) == 5000
    theta = np.column_stack([record[f"theta{i}"] for i in (1, 2, 3)])
    drift = np.linalg.norm(tips(name, theta[::50]) - tips(name, theta0[None])[0], axis=1).max()
    assert drift <= 2e-3
    assert residuals(name, {k: v[::25] for k, v in record.items()}).max() <= TOLERANCE


@pytest.mark.parametrize("name", models())
def test_without_the_three_lines_the_stylus_falls(programs, name, tmp_path):
    """The same program without the three lines: the tip moves more than 10 mm in 3 s."""
    theta0 = falling_posture(name)
    record, out = run(programs[name], "none", 3, theta0, tmp_path / "record.csv")
    theta = np.column_stack([record[f"theta{i}"] for i in (1, 2, 3)])
    assert np.linalg.norm(tips(name, theta[-1:]) - tips(name, theta0[None]), axis=1)[0] > 10e-3
    start, end = (np.array(line.split()[1:], float) for line in out.splitlines()[-2:])
    assert np.linalg.norm(end - start) > 10.0            # mm, what the program itself read


def test_the_compensation_acts_in_the_tick_of_its_state(programs, tmp_path):
    """A hand pushes the Touch's stylus (PHANTOM_PIN_HD_HAND) so that it moves: the command of
    every tick compensates gravity at the state of that same tick (zero ticks late, TOLERANCE),
    and not at the previous tick's (more than 1e-7 N m off where the arm moves)."""
    theta0 = falling_posture("touch")
    record, _ = run(programs["touch"], "force", 0.5, theta0, tmp_path / "record.csv", PHANTOM_PIN_HD_HAND="0.3 0.2 0")
    record = framed(record)
    moving = np.abs(np.diff(record["theta2"])).max()
    assert moving > 1e-5
    assert residuals("touch", record).max() <= TOLERANCE
    late = residuals("touch", record, shift=1)
    assert np.median(late[100:]) > 1e-7


def test_the_headers_values_are_sensables(tmp_path):
    """Every value of the reference (SensAble's hdDefines.h and hdScheduler.h), as the compiler
    sees the installed headers: a program prints each macro."""
    build(tmp_path / "sim", "touch")
    names = sorted(HDDEFINES)
    source = "#include <stdio.h>\n#include <HD/hd.h>\nint main(void) {\n" + "".join(
        f'    printf("%s %lu\\n", "{n}", (unsigned long)({n}));\n' for n in names) + "    return 0;\n}\n"
    (tmp_path / "values.c").write_text(source)
    subprocess.run(["gcc", "-std=c99", "-Wall", "-Werror", f"-I{tmp_path / 'sim' / 'include'}", "values.c", "-o",
                    "values"], cwd=tmp_path, check=True, capture_output=True, text=True)
    printed = dict(line.split() for line in subprocess.run(["./values"], cwd=tmp_path, check=True,
                                                           capture_output=True, text=True).stdout.splitlines())
    assert {n: int(v) for n, v in printed.items()} == {n: int(v) for n, v in HDDEFINES.items()}
    assert [h.name for h in headers()] == sorted(p.name for p in (tmp_path / "sim" / "include" / "HD").iterdir())


BAD = r"""
#include <math.h>
#include <stdio.h>
#include <HD/hd.h>
#include <HD/phantom_pin_sim.h>
static int calls;
static HDCallbackCode HDCALLBACK garbage(void *d) { (void)d; ++calls; return 7; }
static HDCallbackCode HDCALLBACK frames(void *d)
{
    double big[3] = {100.0, 0.0, 0.0}, nan3[3] = {NAN, 0.0, 0.0}, g[3], zero[3] = {0.0, 0.0, 0.0};
    HDErrorInfo e;
    (void)d;
    hdSetDoublev(HD_CURRENT_FORCE, zero);                       /* outside a frame */
    hdBeginFrame(hdGetCurrentDevice());
    hdBeginFrame(hdGetCurrentDevice());                         /* twice */
    hdSetDoublev(HD_CURRENT_FORCE, nan3);                       /* refused */
    hdSetDoublev(HD_CURRENT_GIMBAL_TORQUE, zero);               /* no gimbal motors */
    hdGetDoublev(HD_CURRENT_GIMBAL_ANGLES, g);                  /* the premium has no gimbal */
    hdSetDoublev(HD_CURRENT_FORCE, big);                        /* clamped */
    hdEndFrame(hdGetCurrentDevice());
    hdEndFrame(hdGetCurrentDevice());                           /* not begun */
    while (HD_DEVICE_ERROR(e = hdGetError()))
        printf("frame 0x%04x\n", e.errorCode);
    return HD_CALLBACK_DONE;
}
int main(void)
{
    HDErrorInfo e;
    HHD h = hdInitDevice(HD_DEFAULT_DEVICE);
    if (HD_DEVICE_ERROR(e = hdGetError())) { printf("init 0x%04x %u\n", e.errorCode, h); return 0; }
    hdEnable(HD_FORCE_OUTPUT);
    hdStartScheduler();
    hdStartScheduler();                                         /* twice */
    hdScheduleSynchronous(garbage, 0, HD_DEFAULT_SCHEDULER_PRIORITY);
    hdScheduleSynchronous(frames, 0, HD_DEFAULT_SCHEDULER_PRIORITY);
    while (phantomPinSimTicks() < 5) ;
    hdStopScheduler();
    while (HD_DEVICE_ERROR(e = hdGetError()))
        printf("main 0x%04x\n", e.errorCode);
    printf("garbage %d\n", calls);
    hdDisableDevice(h);
    return 0;
}
"""


@pytest.fixture(scope="module")
def bad(tmp_path_factory):
    folder = tmp_path_factory.mktemp("bad")
    build(folder / "sim", "premium_1_5")
    (folder / "bad.c").write_text(BAD)
    subprocess.run(["gcc", "-std=c99", "-Wall", "-Werror", f"-I{folder / 'sim' / 'include'}", "bad.c",
                    f"-L{folder / 'sim' / 'lib'}", "-lHD", "-lm", "-o", "bad"], cwd=folder, check=True,
                   capture_output=True, text=True)
    return folder


def test_bad_calls_give_openhaptics_errors_and_never_reach_the_plant(bad):
    """Each bad call's OpenHaptics error code (most recent first, popped in the callback that
    made them: the frame's, then the garbage callback's, then the second hdStartScheduler's);
    a callback returning garbage runs once and is unscheduled; the plant got no NaN and the
    clamped force's norm is the nominal maximum (8.5 N, CHAI3D's)."""
    record = bad / "record.csv"
    env = {**os.environ, "LD_LIBRARY_PATH": str(bad / "sim" / "lib"), "PHANTOM_PIN_HD_REALTIME": "0",
           "PHANTOM_PIN_HD_RECORD": str(record)}
    done = subprocess.run(["./bad"], cwd=bad, capture_output=True, text=True, env=env, timeout=60, check=True)
    frame = [int(v, 16) for v in re.findall(r"frame (0x[0-9a-f]+)", done.stdout)]
    codes = {name: value for name, value in HDDEFINES.items()}
    assert frame == [codes[n] for n in ("HD_ILLEGAL_END", "HD_EXCEEDED_MAX_FORCE", "HD_INVALID_ENUM", "HD_INVALID_ENUM",
                                        "HD_INVALID_VALUE", "HD_ILLEGAL_BEGIN", "HD_INVALID_OPERATION",
                                        "HD_INVALID_VALUE", "HD_INVALID_OPERATION")]   # garbage's, started twice
    assert re.findall(r"main (0x[0-9a-f]+)", done.stdout) == []
    assert "garbage 1" in done.stdout
    table = read_record(record)
    forces = np.column_stack([table[f"force{i}"] for i in (1, 2, 3)])
    assert np.isfinite(forces).all()
    assert np.isclose(np.linalg.norm(forces, axis=1).max(), read("premium_1_5").actuation.openhaptics.max_force,
                      rtol=1e-12)


def test_a_bad_environment_fails_hdinitdevice_in_one_line(bad):
    """theta0 outside the stops: hdInitDevice returns HD_INVALID_HANDLE with HD_DEVICE_FAULT,
    the device's reason in one line on stderr, and the host program goes on."""
    env = {**os.environ, "LD_LIBRARY_PATH": str(bad / "sim" / "lib"), "PHANTOM_PIN_HD_THETA0": "0 9 9"}
    done = subprocess.run(["./bad"], cwd=bad, capture_output=True, text=True, env=env, timeout=60)
    assert done.returncode == 0
    assert done.stdout.strip() == f"init 0x{HDDEFINES['HD_DEVICE_FAULT']:04x} {HDDEFINES['HD_INVALID_HANDLE']}"
    assert "PHANTOM_PIN_HD_THETA0" in done.stderr and "outside the stops" in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1


SCHEDULER = r"""
#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <time.h>
#include <HD/hd.h>
#include <HD/phantom_pin_sim.h>
static char order[64];
static int n, ticks_a, ticks_b;
static double last[3], previous[3], mismatch;
static HDCallbackCode HDCALLBACK low(void *d)
{
    (void)d; if (n < 60) order[n++] = 'L';
    ++ticks_b; return HD_CALLBACK_CONTINUE;
}
static HDCallbackCode HDCALLBACK high(void *d)
{
    double now[3];
    (void)d;
    if (n < 60) order[n++] = 'H';
    hdBeginFrame(hdGetCurrentDevice());
    hdGetDoublev(HD_LAST_JOINT_ANGLES, last);
    hdGetDoublev(HD_CURRENT_JOINT_ANGLES, now);
    if (ticks_a > 0)   /* HD_LAST_* is the previous tick's HD_CURRENT_* */
        for (int i = 0; i < 3; ++i) mismatch += (last[i] - previous[i]) * (last[i] - previous[i]);
    previous[0] = now[0]; previous[1] = now[1]; previous[2] = now[2];
    hdEndFrame(hdGetCurrentDevice());
    return ++ticks_a < 300 ? HD_CALLBACK_CONTINUE : HD_CALLBACK_DONE;
}
int main(void)
{
    struct timespec t0, t1;
    HDint rate = 0, dof = 0;
    HHD h = hdInitDevice(HD_DEFAULT_DEVICE);
    HDSchedulerHandle b = hdScheduleAsynchronous(low, 0, HD_MIN_SCHEDULER_PRIORITY);
    HDSchedulerHandle a = hdScheduleAsynchronous(high, 0, HD_MAX_SCHEDULER_PRIORITY);
    hdGetIntegerv(HD_UPDATE_RATE, &rate);
    hdGetIntegerv(HD_OUTPUT_DOF, &dof);
    clock_gettime(CLOCK_MONOTONIC, &t0);
    hdStartScheduler();
    hdWaitForCompletion(a, HD_WAIT_INFINITE);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    printf("done %d %d\n", hdWaitForCompletion(a, HD_WAIT_CHECK_STATUS), hdWaitForCompletion(b, HD_WAIT_CHECK_STATUS));
    hdUnschedule(b);
    int before = ticks_b;
    HDulong t = phantomPinSimTicks();
    while (phantomPinSimTicks() < t + 5) ;
    hdStopScheduler();
    printf("order %.6s\nrate %d dof %d\nunscheduled %d\nmismatch %g\nseconds %f\n", order, rate, dof,
           ticks_b - before <= 1, mismatch, (t1.tv_sec - t0.tv_sec) + 1e-9 * (t1.tv_nsec - t0.tv_nsec));
    hdDisableDevice(h);
    return 0;
}
"""


def test_the_scheduler_runs_by_priority_in_real_time(tmp_path):
    """Callbacks run highest priority first every tick; HD_WAIT_INFINITE returns once the callback
    is done and HD_WAIT_CHECK_STATUS then says so (the other still scheduled); hdUnschedule stops a
    callback; HD_LAST_JOINT_ANGLES is the previous tick's HD_CURRENT_JOINT_ANGLES exactly; 300
    ticks at the default 1000 Hz take at least 0.3 s of the monotonic clock (paced, not faster)."""
    build(tmp_path / "sim", "touch")
    (tmp_path / "scheduler.c").write_text(SCHEDULER)
    subprocess.run(["gcc", "-std=c99", "-Wall", "-Werror", f"-I{tmp_path / 'sim' / 'include'}", "scheduler.c",
                    f"-L{tmp_path / 'sim' / 'lib'}", "-lHD", "-o", "scheduler"], cwd=tmp_path, check=True,
                   capture_output=True, text=True)
    env = {**os.environ, "LD_LIBRARY_PATH": str(tmp_path / "sim" / "lib"), "PHANTOM_PIN_HD_THETA0": "0.2 0.5 0.6"}
    out = subprocess.run(["./scheduler"], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=60,
                         check=True).stdout
    values = dict(line.split(" ", 1) for line in out.splitlines())
    assert values["done"] == "0 1" and values["order"] == "HLHLHL"
    assert values["rate"] == "1000 dof 3" and values["unscheduled"] == "1"
    assert float(values["mismatch"]) == 0.0
    assert float(values["seconds"]) >= 0.299
