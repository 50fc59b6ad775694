"""The device in MuJoCo, driven like phantom_pin.simulate: the Description's MJCF (its motors and
their ctrlrange, frictionloss, armature, joint and tendon limits, the mimic equalities), a
controller sampled at a fixed rate with a zero-order hold, and simulate()'s SimulationResult,
so that one controller runs unchanged against both plants (tests/device/test_mujoco_plant.py compares
them). Needs MuJoCo (``pip install phantom_pin[interop]``).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from phantom_pin.device.device import Device
from phantom_pin.device.run import MAX_STEPS, Controller, SimulationResult, arguments, command, positive
from phantom_pin.exceptions import InvalidInputError, MissingDataError


def simulate_mujoco(theta0: object, duration: float, controller: Controller | None = None, *,
                    dtheta0: object = None, rate: float = 1000.0, device: Device | None = None,
                    timestep: float | None = None) -> SimulationResult:
    """Run ``controller(t, theta, dtheta) -> tau`` (s, rad, rad/s -> N m at the joints) against
    the MuJoCo model of ``device`` (default: the shipped one) from ``theta0`` (rad; at rest, or
    ``dtheta0`` rad/s), at ``rate`` Hz with a zero-order hold, for ``duration`` s. The command
    goes to the MJCF's motors as ctrl = tau / gear; MuJoCo clips it at their ctrlrange
    (actuation.yaml's saturation policy, as simulate). MuJoCo steps the MJCF's timestep
    (config/mjcf.yaml), or ``timestep`` (s), 1 / (rate x timestep) steps per sample, which must be
    a whole number.
    The result's theta and dtheta are MuJoCo's joint1..3; ``tau`` the applied torques."""
    try:
        import mujoco
    except ImportError:
        raise MissingDataError("simulate_mujoco: MuJoCo is not installed (pip install phantom_pin[interop])") \
            from None
    theta, velocity, duration, rate, device, samples = arguments(theta0, dtheta0, duration, rate, controller,
                                                                 device)
    description = device.phantom.description
    model = mujoco.MjModel.from_xml_string(description.mjcf)
    if timestep is not None:
        model.opt.timestep = positive(timestep, "timestep")
    data = mujoco.MjData(model)
    steps = _steps(model.opt.timestep, rate, duration, samples, "rate" if timestep is None else "timestep")
    coupling = device.phantom.coupling
    qpos, dofs, primary_q, primary_v, actuators = _addresses(model, coupling.tree.names[1:], description.prefix)
    gear = model.actuator_gear[actuators, 0].copy()
    low, high = model.actuator_ctrlrange[actuators, 0], model.actuator_ctrlrange[actuators, 1]
    data.qpos[qpos] = coupling.configuration(theta)
    gimbal = description.config.gimbal
    if gimbal is not None:  # its equalities hold it there (description.mjcf)
        data.qpos[[model.joint(name).qposadr[0] for name in device.phantom.gimbal_joints]] = gimbal.locked_at
    data.qvel[dofs] = coupling.tangent(velocity)
    out_theta, out_dtheta = np.empty((samples, 3)), np.empty((samples, 3))
    commanded, applied = np.zeros((samples, 3)), np.zeros((samples, 3))
    # MuJoCo meets a diverging state with a warning (printed, and appended to MUJOCO_LOG.TXT in
    # the working directory), resets the model and goes on; here it ends the run instead.
    diverged = [int(mujoco.mjtWarning.mjWARN_BADQPOS), int(mujoco.mjtWarning.mjWARN_BADQVEL),
                int(mujoco.mjtWarning.mjWARN_BADQACC)]
    previous_handler = mujoco.get_mju_user_warning()
    mujoco.set_mju_user_warning(lambda message: None)     # counted in data.warning, read below
    try:
        mujoco.mj_forward(model, data)
        for k in range(samples):
            t = k / rate
            out_theta[k], out_dtheta[k] = data.qpos[primary_q], data.qvel[primary_v]
            if controller is not None:
                commanded[k] = command(controller(t, out_theta[k].copy(), out_dtheta[k].copy()), t)
            ctrl = np.clip(commanded[k] / gear, low, high)
            applied[k] = ctrl * gear
            if k == samples - 1:
                break
            data.ctrl[actuators] = ctrl
            for _ in range(steps):
                mujoco.mj_step(model, data)
            if any(data.warning[w].number for w in diverged) or not np.isfinite(data.qpos).all():
                raise InvalidInputError(f"controller or dtheta0: MuJoCo's state diverged between t = {t:.6g} s "
                                        "and the next sample")
    finally:
        mujoco.set_mju_user_warning(previous_handler)
    return SimulationResult(
        t=np.arange(samples) / rate, theta=out_theta, dtheta=out_dtheta, tau=applied, tau_commanded=commanded,
        current=None if device.config.actuation.motor is None else device.motor_currents(applied),
        tip=device.phantom.forward_kinematics(out_theta)[:, :3, 3], rate=rate, substeps=steps)


def _addresses(model: Any, names: Sequence[str], prefix: str) -> tuple[list[int], ...]:
    """In the MuJoCo ``model``: the qpos and dof addresses of the tree's joints ``names``, those
    of the three primary joints, and the primaries' actuators (the motors)."""
    qpos = [model.joint(name).qposadr[0] for name in names]
    dofs = [model.joint(name).dofadr[0] for name in names]
    primaries = [f"{prefix}joint{j}" for j in (1, 2, 3)]
    primary_q = [model.joint(name).qposadr[0] for name in primaries]
    primary_v = [model.joint(name).dofadr[0] for name in primaries]
    actuators = [next(i for i in range(model.nu) if model.actuator_trnid[i, 0] == model.joint(name).id)
                 for name in primaries]
    return qpos, dofs, primary_q, primary_v, actuators


def _steps(timestep: float, rate: float, duration: float, samples: int, argument: str) -> int:
    """MuJoCo's steps of ``timestep`` s per sample period at ``rate`` Hz, a whole number;
    InvalidInputError naming ``argument`` (rate or timestep; duration for a run too long at one
    step per sample) beyond MAX_STEPS per sample or per run."""
    steps = 1.0 / (rate * timestep)
    if steps > MAX_STEPS:
        raise InvalidInputError(f"{steps:.3g} MuJoCo steps of {timestep:g} s per sample at {rate:g} Hz, more than "
                                f"{MAX_STEPS:.0e}", argument=argument)
    if abs(steps - round(steps)) > 1e-9 * steps or round(steps) < 1:
        raise InvalidInputError(f"{rate:g} Hz is not 1 / timestep ({1 / timestep:g} Hz) divided by a whole number"
                                + ("; pass timestep" if argument == "rate" else ""), argument=argument)
    whole = int(round(steps))
    if (samples - 1) * whole > MAX_STEPS:
        raise InvalidInputError(f"{duration:g} s at {rate:g} Hz needs {(samples - 1) * whole:.3g} MuJoCo steps of "
                                f"{timestep:g} s, more than {MAX_STEPS:.0e} (minutes)",
                                argument="duration" if whole == 1 else argument)
    return whole
