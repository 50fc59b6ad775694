"""The device behind the libHD stand-in: phantom_pin's Device stepped one servo tick at a time.

The stand-in (``stand_in``, C) starts ``python -m phantom_pin.interfaces.openhaptics.plant`` at
hdInitDevice and talks to it over two pipes. The server first writes one text line, ``ready``
and the device's figures (INFO_FIELDS), or ``error: <message>``; then, for every servo tick, it
reads one command (COMMAND doubles) and answers the state at the next tick (STATE doubles), in
native byte order. The state of a tick is what hdGetDoublev returns within it; the command is
what the tick's last frame set (hdEndFrame), held over the next ``period`` s (zero-order hold).

The device (the environment, read once at the start):

- PHANTOM_PIN_HD_MODEL: the model (phantom_pin.models(); the stand-in's build passes its own as
  the default);
- PHANTOM_PIN_HD_THETA0: three numbers, the report's theta (rad) it starts at, inside the stops
  (default: the model's ``zero`` posture);
- PHANTOM_PIN_HD_GIMBAL: three numbers, OpenHaptics' raw gimbal angles (rad) at which the hand
  holds the stylus (a model with a stylus gimbal, the Touch; default its locked_at). The gimbal
  has no motors: its angles stay where the hand holds them, and the arm carries the stylus as
  a load there (simulate's ``gimbal``);
- PHANTOM_PIN_HD_HOLD: seconds (>= 0, default 0) for which the hand holds the stylus at theta0
  after the scheduler starts; then it lets go;
- PHANTOM_PIN_HD_HAND: three numbers, a hand's force on the stylus (N, OpenHaptics' axes, at
  the gimbal centre) from the moment the hold ends (default none; a test's hand: the stand-in's
  phantomPinSimSetHandForce adds its own);
- PHANTOM_PIN_HD_RECORD: a file to write every tick's state, command and torques to (binary,
  protocol.RECORD_HEADER then RECORD_COLUMNS' doubles; protocol.read_record reads it; not
  overwritten: an existing file is refused).

The plant is simulate()'s (device.plant.Plant: gravity, friction with its stick phase, the
stops, the motors' saturation), with the gimbal held where the hand holds it. A force command F
(N, OpenHaptics' axes, which are frame s's) acts at the gimbal centre as the joint torques
J_p(theta)^T F; a joint-torque command T (mN m on OpenHaptics' angles a) acts as
tau = (da/dtheta)^T T / 1000 (virtual work: a torque does work on the angle it is given on, so
it is the generalized force of that angle; SensAble's CommandJointTorque sample renders its
restoring spring T = k (0 - a) with k > 0 on this reading). The hand's force (the stand-in's
phantomPinSimSetHandForce, N, at the gimbal centre) adds its J_p^T F.
"""

from __future__ import annotations

import math
import os
import struct
import sys
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from phantom_pin.exceptions import InvalidInputError, PhantomPinError
from phantom_pin.interfaces.openhaptics.protocol import COMMAND, ENABLED, QUIT, RECORD_COLUMNS, RECORD_HEADER, STATE

#: The servo period the plant's RK4 substeps are chosen for (s): OpenHaptics' 1 kHz.
PERIOD = 1e-3


def _numbers(env: Mapping[str, str], name: str, default: list[float]) -> list[float]:
    """Three numbers of the environment variable ``name`` of ``env``, or ``default`` where unset."""
    text = env.get(name)
    if text is None or not text.strip():
        return default
    try:
        values = [float(v) for v in text.replace(",", " ").split()]
    except ValueError:
        raise InvalidInputError(f"expected three numbers, got {text!r}", argument=name) from None
    if len(values) != 3 or not all(math.isfinite(v) for v in values):
        raise InvalidInputError(f"expected three finite numbers, got {text!r}", argument=name)
    return values


class Server:
    """The device of the environment (module doc), stepped by ``tick``."""

    def __init__(self, environ: dict[str, str] | None = None) -> None:
        from phantom_pin.description.build import description_of, held
        from phantom_pin.device.device import Device
        from phantom_pin.device.plant import servo_plant
        from phantom_pin.dynamics.phantom import Phantom
        from phantom_pin.interfaces.conventions import openhaptics_from_theta, openhaptics_origin

        env = os.environ if environ is None else environ
        description = description_of(env.get("PHANTOM_PIN_HD_MODEL") or "premium_1_5", "PHANTOM_PIN_HD_MODEL")
        config = description.config
        if config.actuation.openhaptics is None:
            raise InvalidInputError(f"the model {config.name!r} has no openhaptics section in actuation.yaml",
                                    argument="PHANTOM_PIN_HD_MODEL")
        self.has_gimbal = config.gimbal is not None
        if not self.has_gimbal and env.get("PHANTOM_PIN_HD_GIMBAL", "").strip():
            raise InvalidInputError(f"the model {config.name!r} has no stylus gimbal", argument="PHANTOM_PIN_HD_GIMBAL")
        locked = list(config.gimbal.locked_at) if config.gimbal else [0.0] * 3
        self.gimbal = _numbers(env, "PHANTOM_PIN_HD_GIMBAL", locked)
        phantom = Phantom(held(description, self.gimbal) if self.has_gimbal else description)
        self.device = device = Device(phantom)
        theta0 = _numbers(env, "PHANTOM_PIN_HD_THETA0", list(config.limits.postures["zero"]))
        if not device.within_limits(np.array(theta0)):
            raise InvalidInputError(f"{theta0!r} rad is outside the stops", argument="PHANTOM_PIN_HD_THETA0")
        hold_text = env.get("PHANTOM_PIN_HD_HOLD", "0").strip() or "0"
        try:
            self.hold = float(hold_text)
        except ValueError:
            self.hold = math.nan
        if not 0 <= self.hold < math.inf:
            raise InvalidInputError(f"expected a time >= 0 s, got {hold_text!r}", argument="PHANTOM_PIN_HD_HOLD")
        self.plant, self.steps = servo_plant(device, np.array(theta0), PERIOD)
        self.q, self.v = list(theta0), [0.0, 0.0, 0.0]
        self.theta0 = list(theta0)
        self.hand = np.array(_numbers(env, "PHANTOM_PIN_HD_HAND", [0.0, 0.0, 0.0]))
        self._jacobian = device.tip_jacobian(np.array(theta0))    # J_p at (q, v), m/rad: state() keeps it
        self.time, self.tick_count = 0.0, 0
        self.to_theta = openhaptics_from_theta(np.eye(3)).T      # da/dtheta (OpenHaptics' angles are linear in theta)
        self.origin = openhaptics_origin(phantom) if self.has_gimbal else np.zeros(3)
        self.phantom = phantom
        self.info = self._info(config)
        record = env.get("PHANTOM_PIN_HD_RECORD", "").strip()
        self.record = None
        if record:
            path = Path(record)
            if path.exists():
                raise InvalidInputError(f"{path} exists (the record is never overwritten)",
                                        argument="PHANTOM_PIN_HD_RECORD")
            self.record = path.open("wb")
            self.record.write(RECORD_HEADER.encode())

    def _info(self, config) -> list[float]:
        """INFO_FIELDS' numbers: the nominal maximum force, the continuous one (the least tip force
        the motors' continuous torque renders along OpenHaptics' +-x, +-y, +-z at the zero posture,
        gravity held: Device.tip_force_capacity), the stiffness, the peak joint torques (mN m on
        OpenHaptics' angles), whether a gimbal is there, the workspace box (mm, OpenHaptics'
        coordinates: the tip's extremes over device.feel.workspace_grid, within a grid step of
        workspace_box's refined ones, which would cost each start scipy.optimize's import)."""
        from phantom_pin.device.feel import workspace_grid

        openhaptics, device = config.actuation.openhaptics, self.device
        zero = np.array(config.limits.postures["zero"])
        axes = np.vstack([np.eye(3), -np.eye(3)])
        continuous = float(min(openhaptics.max_force, device.tip_force_capacity(np.tile(zero, (6, 1)), axes).min()))
        peak = (np.array(config.actuation.peak) * 1000.0).tolist()
        tips = (workspace_grid(device)[1] + self.origin) * 1000.0
        lower, upper = tips.min(axis=0), tips.max(axis=0)
        return [openhaptics.max_force, continuous, openhaptics.max_stiffness, *peak, float(self.has_gimbal),
                *lower.tolist(), *upper.tolist()]

    def state(self) -> list[float]:
        """STATE's numbers of the current (theta, dtheta)."""
        from phantom_pin.interfaces.conventions import openhaptics_from_theta, transform_of_rigid

        theta, rates = np.array(self.q), np.array(self.v)
        if self.has_gimbal:
            pose = self.phantom.stylus_pose(theta, self.gimbal)
        else:                            # no stylus gimbal: the transform's rotation is the identity
            pose = np.eye(4)
            pose[:3, 3] = self.phantom.forward_kinematics(theta)[:3, 3]
        transform = transform_of_rigid(pose, self.origin)      # the model's own pose: rigid and finite
        self._jacobian = self.device.tip_jacobian(theta)       # the next tick's, at this state
        velocity = self._jacobian @ rates * 1000.0
        return [*openhaptics_from_theta(theta).tolist(), *self.gimbal, *transform[12:15].tolist(),
                *velocity.tolist(), *transform.tolist(), 0.0]

    def tick(self, command: tuple[float, ...]) -> list[float]:
        """One servo tick under ``command`` (COMMAND's numbers): the next tick's state."""
        from phantom_pin.device.plant import Diverged

        enabled = command[0] == ENABLED
        force, torque = np.array(command[1:4]), np.array(command[4:7])
        period, hand = command[7], np.array(command[8:11]) + self.hand
        theta, jacobian = np.array(self.q), self._jacobian
        tau = jacobian.T @ (hand + force) + self.to_theta @ torque / 1000.0 if enabled else jacobian.T @ hand
        held = self.time < self.hold
        applied = [0.0, 0.0, 0.0] if held else self.plant.saturate(tau.tolist())
        if self.record is not None:
            row = (self.tick_count, self.time, float(enabled), command[11], *force, *torque, *hand, *self.q, *self.v,
                   *(self.to_theta.T @ theta).tolist(), *self.gimbal, *tau.tolist(), *applied)
            self.record.write(struct.pack(f"={len(RECORD_COLUMNS)}d", *row))
        failed = False
        if held:
            self.q, self.v = list(self.theta0), [0.0, 0.0, 0.0]
        else:
            try:
                self.q, self.v = self.plant.hold(self.q, self.v, applied, period, max(1, round(period / PERIOD)) *
                                                 self.steps)
            except Diverged:
                failed = True
        self.time += period
        self.tick_count += 1
        out = self.state()
        out[-1] = 1.0 if failed else 0.0
        return out

    def close(self) -> None:
        if self.record is not None:
            self.record.close()
            self.record = None


def _read(stream, size: int) -> bytes:
    data = b""
    while len(data) < size:
        chunk = stream.read(size - len(data))
        if not chunk:
            return b""
        data += chunk
    return data


def main() -> int:
    """The server over standard input and output (module doc)."""
    out = sys.stdout.buffer
    try:
        server = Server()
    except PhantomPinError as error:
        out.write(f"error: {error}\n".replace("\n", " ").rstrip().encode() + b"\n")
        out.flush()
        return 2
    openhaptics = server.device.config.actuation.openhaptics
    assert openhaptics is not None       # Server refuses a model without one
    model_type = openhaptics.model_type
    out.write(("ready " + " ".join(repr(float(x)) for x in server.info) + " " + model_type + "\n").encode())
    out.write(struct.pack(f"={STATE}d", *server.state()))
    out.flush()
    command_format, stdin = f"={COMMAND}d", sys.stdin.buffer
    try:
        while True:
            data = _read(stdin, struct.calcsize(command_format))
            if not data:
                break
            command = struct.unpack(command_format, data)
            if command[0] == QUIT:
                break
            out.write(struct.pack(f"={STATE}d", *server.tick(command)))
            out.flush()
    except BrokenPipeError:
        pass
    finally:
        server.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
