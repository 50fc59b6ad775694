"""interfaces.openhaptics.plant: the stand-in's device run in this process (Server of an
environment): its refusals naming the environment variable, the hold that keeps the arm at
theta0, a joint-torque command's torque on theta against the angles' map by finite differences
(virtual work: tau = (da/dtheta)^T T / 1000), and its record read back by protocol.read_record."""

import numpy as np
import pytest

from phantom_pin import InvalidInputError
from phantom_pin.interfaces.conventions import openhaptics_from_theta
from phantom_pin.interfaces.openhaptics import protocol
from phantom_pin.interfaces.openhaptics.plant import PERIOD, Server

THETA0 = "0.1 0.4 0.6"


@pytest.mark.parametrize("variable, value, match", [
    ("PHANTOM_PIN_HD_THETA0", "0 zero 0", "expected three numbers"),
    ("PHANTOM_PIN_HD_THETA0", "0 0", "expected three finite numbers"),
    ("PHANTOM_PIN_HD_THETA0", "0 0 nan", "expected three finite numbers"),
    ("PHANTOM_PIN_HD_THETA0", "3 0 0", "outside the stops"),
    ("PHANTOM_PIN_HD_HOLD", "-1", "expected a time >= 0 s"),
    ("PHANTOM_PIN_HD_HOLD", "soon", "expected a time >= 0 s"),
    ("PHANTOM_PIN_HD_GIMBAL", "0 0 0", "has no stylus gimbal"),
    ("PHANTOM_PIN_HD_MODEL", "premium_9", "premium_9"),
])
def test_a_bad_environment_is_refused_naming_its_variable(variable, value, match, monkeypatch):
    """Read from os.environ by default, and from ``environ`` where given (every variable: the
    three-number ones had been read from os.environ whatever ``environ`` said)."""
    monkeypatch.setenv("PHANTOM_PIN_HD_MODEL", "premium_1_5")
    monkeypatch.setenv(variable, value)
    with pytest.raises(InvalidInputError, match=match) as refused:
        Server()
    assert refused.value.argument == variable
    monkeypatch.delenv(variable)
    with pytest.raises(InvalidInputError, match=match) as refused:
        Server({"PHANTOM_PIN_HD_MODEL": "premium_1_5", variable: value})
    assert refused.value.argument == variable


def test_the_record_is_never_overwritten(tmp_path):
    """(``environ`` given: the record's variable is read from it.)"""
    path = tmp_path / "record.bin"
    path.write_bytes(b"")
    with pytest.raises(InvalidInputError, match="never overwritten") as refused:
        Server({"PHANTOM_PIN_HD_RECORD": str(path)})
    assert refused.value.argument == "PHANTOM_PIN_HD_RECORD"


def test_a_held_arm_stays_and_a_joint_torque_acts_by_virtual_work(tmp_path, monkeypatch):
    """Held for 3 ticks (PHANTOM_PIN_HD_HOLD 2.5 ms): theta stays theta0 and nothing is applied;
    the state's joint angles are OpenHaptics' of theta. The record holds every tick's time
    (k PERIOD), the command and tau = (da/dtheta)^T T / 1000, da/dtheta by central differences
    of openhaptics_from_theta (exact: the map is linear; 1e-12)."""
    record = tmp_path / "record.bin"
    for variable, value in (("PHANTOM_PIN_HD_THETA0", THETA0), ("PHANTOM_PIN_HD_HOLD", "0.0025"),
                            ("PHANTOM_PIN_HD_RECORD", str(record))):
        monkeypatch.setenv(variable, value)
    server = Server()
    theta0 = np.array([float(v) for v in THETA0.split()])
    torque = np.array([3.0, -5.0, 7.0])                           # mN m on OpenHaptics' angles
    command = [protocol.ENABLED, 0, 0, 0, *torque, PERIOD, 0, 0, 0, 1.0]
    assert len(command) == protocol.COMMAND
    states = [server.state()] + [server.tick(command) for _ in range(5)]
    server.close()
    assert all(len(state) == protocol.STATE and state[-1] == 0.0 for state in states)
    joint = protocol.STATE_LAYOUT["JOINT"]
    for state in states[:4]:
        np.testing.assert_array_equal(state[joint:joint + 3], openhaptics_from_theta(theta0))
    assert states[5][joint:joint + 3] != states[3][joint:joint + 3]    # let go: the torque moves it
    rows = protocol.read_record(record)
    np.testing.assert_allclose(rows["t"], np.arange(5) * PERIOD, rtol=0, atol=1e-15)
    np.testing.assert_array_equal(rows["tick"], np.arange(5))
    h = 1e-6
    jacobian = np.stack([(openhaptics_from_theta(theta0 + h * e) - openhaptics_from_theta(theta0 - h * e)) / (2 * h)
                         for e in np.eye(3)], axis=1)          # da/dtheta
    expected = jacobian.T @ torque / 1000
    for k in range(5):
        np.testing.assert_allclose([rows[f"tau{j}"][k] for j in (1, 2, 3)], expected, rtol=0, atol=1e-12)
        np.testing.assert_array_equal([rows[f"torque{j}"][k] for j in (1, 2, 3)], torque)
    applied = np.stack([rows[f"applied{j}"] for j in (1, 2, 3)], axis=1)
    assert (applied[:3] == 0).all() and np.abs(applied[3:]).max() > 0      # held: nothing applied
    np.testing.assert_array_equal(rows["enabled"], 1.0)
