"""The pyOpenHaptics compensator (phantom_pin.interfaces.openhaptics.Compensator): its forces and
joint torques against references independent of Phantom (tests/references/openhaptics.py), the
friction law added at the caller's rates, bad input named; and an unchanged pyOpenHaptics (PyPI)
callback with it, on the libHD stand-in, floats the stylus of every model; pyOpenHaptics'
hd_define.py agrees with SensAble's values but where it is known to differ."""

import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from phantom_pin.config import models, read
from phantom_pin.config.sampling import random_states
from phantom_pin.config.types import Friction
from phantom_pin.exceptions import InvalidInputError
from phantom_pin.interfaces.openhaptics import Compensator, build, read_record
from references.openhaptics import (
    HDDEFINES,
    PYOPENHAPTICS_DIFFERS,
    PYOPENHAPTICS_SPELLING,
    TOLERANCE,
    falling_posture,
    framed,
    gravity_and_jacobian,
    pyopenhaptics_defines,
    residuals,
    tips,
)

SIGN = np.array([-1.0, 1.0, 1.0])     # theta = SIGN * OpenHaptics' angles (Ubitrack's eq., tests/codegen)


@pytest.mark.parametrize("name", models())
def test_forces_and_joint_torques_compensate_gravity(name):
    """50 seeded states inside the stops (the Touch's gimbal inside its ranges): J^T F and the
    joint torques (mN m on OpenHaptics' angles, SIGN back to theta) equal the reference's
    gravity to TOLERANCE N m."""
    config = read(name)
    theta = random_states(config.limits, 50, seed=51)[0]
    gimbal = None if config.gimbal is None else \
        np.random.default_rng(52).uniform(config.gimbal.lower, config.gimbal.upper, (50, 3))
    force, torque = Compensator(name), Compensator(name, mode="joint_torque")
    for k, t in enumerate(theta):
        g = None if gimbal is None else gimbal[k]
        gravity, jacobian = gravity_and_jacobian(name, t, g)
        angles = SIGN * t
        assert np.abs(jacobian.T @ force(angles, g) - gravity).max() <= TOLERANCE
        assert np.abs(SIGN * np.array(torque(angles, g)) / 1000 - gravity).max() <= TOLERANCE


def test_friction_adds_the_law_at_the_callers_rates():
    """With friction, the joint torques gain viscous rate + Coulomb sign(rate) (actuation.yaml's
    numbers read here) at the rates of the OpenHaptics angles given, on theta; none for a joint
    within the dead band (the third, at rest)."""
    law = read("touch").actuation.friction
    angles, rates = np.array([0.1, 0.4, 0.3]), np.array([0.5, -0.2, 0.0])
    plain = np.array(Compensator("touch", "joint_torque")(angles))
    with_friction = np.array(Compensator("touch", "joint_torque", ("gravity", "friction"))(angles, rates=rates))
    theta_rates = SIGN * rates
    expected = np.array(law.viscous) * theta_rates + np.array(law.coulomb) * np.sign(theta_rates)
    assert np.allclose(SIGN * (with_friction - plain) / 1000, expected, rtol=0, atol=1e-15)


def test_bad_input_names_the_argument():
    for call, argument in ((lambda: Compensator("premium_1_5", mode="cartesian"), "mode"),
                           (lambda: Compensator("nope"), "model"),
                           (lambda: Compensator("touch")([0.0, np.nan, 0.0]), "joints"),
                           (lambda: Compensator("touch")([0.0, 0.1]), "joints"),
                           (lambda: Compensator("touch")([0.0, 0.1, 0.2], [0, 0, np.inf]), "gimbals"),
                           (lambda: Compensator("premium_1_5")([0.0, 0.1, 0.2], [0, 0, 0]), "gimbals"),
                           (lambda: Compensator("touch", compensate="gravity"), "compensate"),
                           (lambda: Compensator("touch", compensate=("gravity", "wind")), "compensate"),
                           (lambda: Compensator("touch", compensate=("inertia",)), "kappa"),
                           (lambda: Compensator("touch", compensate=("inertia",), kappa=1.0), "kappa"),
                           (lambda: Compensator("touch", kappa=-0.1), "kappa"),
                           (lambda: Compensator("touch", dead_band=-1.0), "dead_band"),
                           (lambda: Compensator("touch", cutoff=600.0), "cutoff"),
                           (lambda: Compensator("touch", friction="yes"), "friction"),
                           (lambda: Compensator("touch", compensate=("gravity", "friction"),
                                                friction=Friction((0.0,) * 3, (0.0,) * 3)), "compensate")):
        with pytest.raises(InvalidInputError) as error:
            call()
        assert error.value.argument == argument


def test_pyopenhaptics_values_agree_with_sensables_but_where_known():
    """Every value of the reference that pyOpenHaptics defines is SensAble's, but
    PYOPENHAPTICS_DIFFERS (its HD_INVALID_OPERATION is HD_INVALID_INPUT_TYPE's 0x0103)."""
    theirs = pyopenhaptics_defines()
    compared = 0
    for name, value in HDDEFINES.items():
        key = PYOPENHAPTICS_SPELLING.get(name, name)
        if key in theirs:
            assert theirs[key] == PYOPENHAPTICS_DIFFERS.get(name, value), name
            compared += 1
    assert compared >= 80


CALLBACK = textwrap.dedent("""
    import ctypes, sys, time
    import pyOpenHaptics.hd as hd
    from pyOpenHaptics.hd_callback import hd_callback
    from pyOpenHaptics.hd_device import HapticDevice
    from phantom_pin.interfaces.openhaptics import Compensator

    compensate = Compensator(sys.argv[1])
    stylus = compensate.has_gimbal

    @hd_callback
    def servo():
        hd.set_force(compensate(hd.get_joints(), hd.get_gimbals() if stylus else None))

    device = HapticDevice(servo)
    ticks = ctypes.CDLL("libHD.so").phantomPinSimTicks
    ticks.restype = ctypes.c_ulong
    while ticks() < 5000:
        time.sleep(0.01)
    device.close()
""")


@pytest.mark.parametrize("name", models())
def test_a_pyopenhaptics_callback_floats_the_stylus(name, tmp_path):
    """pyOpenHaptics as published (its HapticDevice, hd_callback, get_joints, get_gimbals,
    set_force) with the compensator, on the stand-in: 5 s (at least) within 2 mm of where the
    stylus started, every recorded command J^T F = gravity (TOLERANCE)."""
    build(tmp_path / "sim", name)
    theta0 = falling_posture(name)
    env = {**os.environ, "LD_LIBRARY_PATH": str(tmp_path / "sim" / "lib"), "PHANTOM_PIN_HD_REALTIME": "0",
           "PHANTOM_PIN_HD_THETA0": " ".join(repr(float(t)) for t in theta0),
           "PHANTOM_PIN_HD_RECORD": str(tmp_path / "record.csv")}
    (tmp_path / "callback.py").write_text(CALLBACK)
    done = subprocess.run([sys.executable, "callback.py", name], cwd=tmp_path, env=env, capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 0, done.stderr
    record = framed(read_record(tmp_path / "record.csv"))
    assert len(record["tick"]) >= 5000
    assert record["enabled"].all()
    theta = np.column_stack([record[f"theta{i}"] for i in (1, 2, 3)])
    drift = np.linalg.norm(tips(name, theta[::50]) - tips(name, theta0[None])[0], axis=1).max()
    assert drift <= 2e-3
    assert residuals(name, {k: v[1::50] for k, v in record.items()}).max() <= TOLERANCE
