"""Issue 42 (Hardening 5), the rest: the files the command line writes and reads (nothing
written on failure; the model and convention a trajectory or log was written for), and the
stylus gimbal's angles in every dynamics function, simulate and the command line. Each test
compares with something independent of the code under test: the file system itself, the
six-joint Touch built by Pinocchio from the URDF, finite differences, energy."""

import json
import os
import stat

import numpy as np
import pinocchio as pin
import pytest

from phantom_pin import Device, InvalidInputError, Phantom, config, simulate
from phantom_pin.config.sampling import random_states


@pytest.mark.parametrize("output, scene", [("model.xml", "/dev/full"), ("/dev/full", "scene.xml")])
def test_mjcf_writes_neither_file_when_one_cannot_be_written(tmp_path, cli, output, scene):
    """`mjcf -o A --scene /dev/full` wrote A, then failed on the scene: nothing may be written
    on failure. Either file unwritable (a full device): the folder stays empty, one line names
    the option whose file failed."""
    paths = [p if p.startswith("/dev") else str(tmp_path / p) for p in (output, scene)]
    code, out, err = cli("mjcf", "-o", paths[0], "--scene", paths[1], "--force")
    option = "--scene" if scene.startswith("/dev") else "--output"
    assert (code, out, err) == (2, "", f"phantom-pin: error: {option}: cannot write /dev/full (No space left on "
                                       "device)\n")
    assert list(tmp_path.iterdir()) == []


def test_written_files_take_the_umask_and_an_overwritten_file_keeps_its_mode(tmp_path, cli):
    """The files are staged beside their targets and renamed into place: a new file gets the
    mode open() would give it (0666 less the umask), an overwritten one keeps its own, and no
    temporary file is left behind."""
    mask = os.umask(0o027)
    try:
        assert cli("mjcf", "-o", tmp_path / "m.xml", "--scene", tmp_path / "s.xml")[0] == 0
        os.chmod(tmp_path / "s.xml", 0o600)
        (tmp_path / "s.xml").write_text("old\n")
        assert cli("mjcf", "-o", tmp_path / "m.xml", "--scene", tmp_path / "s.xml", "--force")[0] == 0
    finally:
        os.umask(mask)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.xml", "s.xml"]
    assert stat.S_IMODE((tmp_path / "m.xml").stat().st_mode) == 0o640
    assert stat.S_IMODE((tmp_path / "s.xml").stat().st_mode) == 0o600
    assert "m.xml" in (tmp_path / "s.xml").read_text()
    (tmp_path / "link.xml").symlink_to(tmp_path / "m.xml")  # written through, as open() would
    (tmp_path / "m.xml").write_text("old\n")
    assert cli("mjcf", "-o", tmp_path / "link.xml", "--force")[0] == 0
    assert (tmp_path / "link.xml").is_symlink() and "<mujoco" in (tmp_path / "m.xml").read_text()


# -- the stylus gimbal held at given angles ---------------------------------------------------
TOUCH = config.read("touch")
#: far from locked_at (0): the stylus's load differs by percents of the arm's torques
HELD = np.array([1.0, -0.8, 1.2])


class Six:
    """The Touch's six-joint model built here from its committed URDF with Pinocchio alone (the
    gimbal free, the configuration's g along base_link's -z): the arm's rows and columns of its
    dynamics with the gimbal at rest are what the arm's methods with gimbal= compute."""

    def __init__(self):
        self.model = pin.buildModelFromXML(config.MODELS["touch"].urdf.read_text(), mimic=True)
        self.model.gravity = pin.Motion(np.array([0.0, 0.0, -TOUCH.gravity]), np.zeros(3))
        self.data = self.model.createData()
        names = [f"joint{j}" for j in range(1, 7)]
        self.order = [self.model.joints[self.model.getJointId(n)].idx_q for n in names]
        self.arm = self.order[:3]

    def q(self, theta, gimbal=None):
        """The six joints' vector of the arm's theta (rad), with the gimbal's angles or zero."""
        q = np.zeros(6)
        q[self.order] = np.concatenate([theta, np.zeros(3) if gimbal is None else gimbal])
        return q

    def mass(self, theta, gimbal):
        return pin.crba(self.model, self.data, self.q(theta, gimbal))[np.ix_(self.arm, self.arm)]

    def torques(self, theta, gimbal, dtheta, ddtheta):
        return pin.rnea(self.model, self.data, self.q(theta, gimbal), self.q(dtheta), self.q(ddtheta))[self.arm]

    def pose(self, theta, gimbal, frame):
        """A frame's pose in frame s (report_s), (4, 4)."""
        pin.framesForwardKinematics(self.model, self.data, self.q(theta, gimbal))
        s = self.data.oMf[self.model.getFrameId("report_s")]
        return (s.inverse() * self.data.oMf[self.model.getFrameId(frame)]).homogeneous

    def energy(self, theta, gimbal, dtheta):
        """T + V (J): 1/2 dtheta^T M dtheta, and the sum of -m g . c over the bodies (each centre
        of mass c placed by the forward kinematics)."""
        pin.forwardKinematics(self.model, self.data, self.q(theta, gimbal))
        potential = -sum(inertia.mass * self.model.gravity.linear @ placement.act(inertia.lever)
                         for inertia, placement in zip(self.model.inertias, self.data.oMi))
        return 0.5 * dtheta @ self.mass(theta, gimbal) @ dtheta + potential


@pytest.fixture(scope="module")
def six():
    return Six()


@pytest.fixture(scope="module")
def touch():
    return Phantom.from_model("touch")


def _held_states(n, seed):
    """``n`` seeded (theta, dtheta, ddtheta, gimbal): theta inside the Touch's stops, gimbal
    angles uniform inside the gimbal's range."""
    theta, dtheta, ddtheta = random_states(TOUCH.limits, n, seed=seed)
    gimbal = np.random.default_rng(seed).uniform(TOUCH.gimbal.lower, TOUCH.gimbal.upper, (n, 3))
    return theta, dtheta, ddtheta, gimbal


def _christoffel(six, theta, gimbal, dtheta, step=1e-6):
    """C(theta, dtheta) of the Christoffel symbols of M's central differences (step rad):
    C_ij = sum_k 1/2 (dM_ij/dq_k + dM_ik/dq_j - dM_jk/dq_i) dtheta_k."""
    dm = np.array([(six.mass(theta + step * e, gimbal) - six.mass(theta - step * e, gimbal)) / (2 * step)
                   for e in np.eye(3)])  # dm[k] = dM/dq_k
    return 0.5 * (np.einsum("kij,k->ij", dm, dtheta) + np.einsum("jik,k->ij", dm, dtheta)
                  - np.einsum("ijk,k->ij", dm, dtheta))


def test_the_arms_dynamics_with_the_gimbal_held_are_the_six_joint_models(touch, six):
    """Missing: mass_matrix, coriolis_matrix, inverse_dynamics and forward_dynamics took no gimbal
    angles (gravity alone did). Against the six-joint model built here from the URDF, at 40
    seeded states inside the stops with gimbal angles across their range: M's arm block, rnea's
    and gravity's arm rows (1e-12 relative), the accelerations of M's solve (1e-9), and C
    against the Christoffel symbols of M's central differences (1e-6 of C's largest entry;
    C dtheta also against rnea's bias, 1e-12). At locked_at they would differ by percents."""
    scale = 1e-12
    for theta, dtheta, ddtheta, gimbal in zip(*_held_states(40, seed=4201)):
        mass, torques = six.mass(theta, gimbal), six.torques(theta, gimbal, dtheta, ddtheta)
        gravity = six.torques(theta, gimbal, 0 * dtheta, 0 * ddtheta)
        bias = six.torques(theta, gimbal, dtheta, 0 * ddtheta)
        np.testing.assert_allclose(touch.mass_matrix(theta, gimbal), mass, rtol=0, atol=scale * np.abs(mass).max())
        np.testing.assert_allclose(touch.gravity(theta, gimbal), gravity, rtol=0, atol=scale * np.abs(gravity).max())
        np.testing.assert_allclose(touch.inverse_dynamics(theta, dtheta, ddtheta, gimbal), torques, rtol=0,
                                   atol=scale * np.abs(torques).max())
        np.testing.assert_allclose(touch.forward_dynamics(theta, dtheta, torques, gimbal),
                                   np.linalg.solve(mass, torques - bias), rtol=1e-9, atol=1e-9 * np.abs(ddtheta).max())
        c = touch.coriolis_matrix(theta, dtheta, gimbal)
        np.testing.assert_allclose(c, _christoffel(six, theta, gimbal, dtheta), rtol=0, atol=1e-6 * np.abs(c).max())
        np.testing.assert_allclose(c @ dtheta, bias - gravity, rtol=0, atol=scale * np.abs(bias - gravity).max())
    locked = touch.inverse_dynamics(theta, dtheta, ddtheta)
    assert np.abs(locked - torques).max() > 1e-3 * np.abs(torques).max()  # the gimbal's angles show


def test_the_coriolis_matrix_with_the_gimbal_held_keeps_the_energy_balance(touch):
    """dM/dt - 2 C is skew-symmetric (the power balance of a mechanical system): dM/dt by central
    differences of mass_matrix(theta + t dtheta, gimbal), at 20 seeded states; 1e-6 of C's
    largest entry (the differences' error)."""
    step = 1e-6
    for theta, dtheta, _, gimbal in zip(*_held_states(20, seed=4202)):
        dm = (touch.mass_matrix(theta + step * dtheta, gimbal) - touch.mass_matrix(theta - step * dtheta, gimbal)) / (
            2 * step)
        skew = dm - 2 * touch.coriolis_matrix(theta, dtheta, gimbal)
        np.testing.assert_allclose(skew, -skew.T, rtol=0, atol=1e-6 * np.abs(dm).max())


@pytest.mark.parametrize("method, count", [("gravity", 1), ("mass_matrix", 1), ("coriolis_matrix", 2),
                                           ("inverse_dynamics", 3), ("forward_dynamics", 3), ("stylus_pose", 1),
                                           ("stylus_tip_pose", 1)])
def test_one_gimbal_broadcasts_over_a_batch_of_states(touch, six, method, count):
    """Missing: stylus_pose refused one gimbal with a batch of theta ("arguments must have the same
    shape"). Theta's batch (2, 5, 3) with one gimbal (3,), and with one gimbal per row of the
    last axis (5, 3): each state's result equals its single call's; the poses against the
    six-joint model's frames (1e-12 m)."""
    theta, dtheta, ddtheta, gimbal = _held_states(10, seed=4203)
    values = [v.reshape(2, 5, 3) for v in (theta, dtheta, ddtheta)[:count]]
    function = getattr(touch, method)
    for g in (gimbal[0], gimbal[:5]):
        batch = function(*values, gimbal=g)
        assert batch.shape[:2] == (2, 5)
        for i, j in np.ndindex(2, 5):
            row = g if g.ndim == 1 else g[j]
            one = function(*(v[i, j] for v in values), gimbal=row)
            np.testing.assert_allclose(batch[i, j], one, rtol=1e-13, atol=1e-15)
            if method.startswith("stylus"):
                frame = "stylus" if method == "stylus_pose" else "stylus_tip"
                np.testing.assert_allclose(one, six.pose(values[0][i, j], row, frame), rtol=0, atol=1e-12)


@pytest.mark.parametrize("gimbal, message", [
    ([0.1, 0.2], r"gimbal: expected shape \(3,\) or \(\.\.\., 3\)"),
    ([0.1, np.nan, 0.2], "gimbal: contains NaN or inf"),
    ([True, False, True], "gimbal: expected real numbers, got booleans"),
    (np.zeros((4, 3)), r"gimbal: shape \(4, 3\) does not broadcast against theta's \(5, 3\)"),
])
@pytest.mark.parametrize("method", ["mass_matrix", "coriolis_matrix", "inverse_dynamics", "forward_dynamics",
                                    "gravity", "stylus_pose"])
def test_a_bad_gimbal_is_refused_by_name(touch, method, gimbal, message):
    count = {"coriolis_matrix": 2, "inverse_dynamics": 3, "forward_dynamics": 3}.get(method, 1)
    shape = (5, 3) if np.ndim(gimbal) == 2 else (3,)
    with pytest.raises(InvalidInputError, match=f"^{message}"):
        getattr(touch, method)(*[np.full(shape, 0.2)] * count, gimbal=gimbal)


@pytest.mark.parametrize("method, count", [("mass_matrix", 1), ("coriolis_matrix", 2), ("inverse_dynamics", 3),
                                           ("forward_dynamics", 3), ("gravity", 1)])
def test_a_model_without_a_gimbal_refuses_gimbal_angles_by_name(method, count):
    with pytest.raises(InvalidInputError, match="^gimbal: the model 'premium_1_5' has no stylus gimbal"):
        getattr(Phantom(), method)(*[np.full(3, 0.2)] * count, gimbal=[0.1, 0.2, 0.3])


def test_simulate_holds_the_gimbal_where_it_is_asked_and_keeps_the_energy(six):
    """Missing: simulate held the gimbal at locked_at only. A 0.5 s free swing (no friction, no
    stops, no clipping) with the gimbal held at HELD: the total energy of the six-joint model
    built here at HELD stays within 1e-8 of its swing's kinetic energy at every sample (RK4's
    error); evaluated at locked_at instead it drifts by more than 1e-4 of it, so the run used
    HELD. Gimbal angles outside the gimbal's range are refused by name."""
    result = simulate([0.2, 0.3, 0.5], 0.5, None, friction=False, hard_stops=False, saturation=False,
                      device=Device(Phantom.from_model("touch")), gimbal=HELD, substeps=4)
    energy = np.array([six.energy(q, HELD, v) for q, v in zip(result.theta, result.dtheta)])
    kinetic = max(0.5 * v @ six.mass(q, HELD) @ v for q, v in zip(result.theta, result.dtheta))
    assert kinetic > 1e-3
    assert np.abs(energy - energy[0]).max() < 1e-8 * kinetic
    elsewhere = np.array([six.energy(q, None, v) for q, v in zip(result.theta, result.dtheta)])
    assert np.abs(elsewhere - elsewhere[0]).max() > 1e-4 * kinetic
    with pytest.raises(InvalidInputError, match=r"^gimbal: joint6 at 9.0 rad is outside its range"):
        simulate([0.2, 0.3, 0.5], 0.01, device=Device(Phantom.from_model("touch")), gimbal=[0.0, 0.0, 9.0])


def test_fk_and_dynamics_take_gimbal_angles(cli, six):
    """Missing: --gimbal for fk and dynamics. fk prints the stylus frame's and its tip's poses,
    dynamics holds the gimbal there: against the six-joint model built here (1e-12)."""
    theta, dtheta, ddtheta = [0.1, 0.3, 0.5], [0.4, -1.0, 2.0], [3.0, -2.0, 1.0]
    code, out, err = cli("--model", "touch", "fk", *theta, "--gimbal", *HELD, "--json")
    assert (code, err) == (0, "")
    poses = json.loads(out)
    for key, frame in (("stylus", "stylus"), ("stylus_tip", "stylus_tip"), ("g_st", "tip")):
        np.testing.assert_allclose(poses[key], six.pose(theta, HELD, frame), rtol=0, atol=1e-12)
    code, out, err = cli("--model", "touch", "dynamics", "--theta", *theta, "--dtheta", *dtheta, "--ddtheta",
                         *ddtheta, "--gimbal", *HELD, "--json")
    assert (code, err) == (0, "")
    results = json.loads(out)
    torques = six.torques(np.array(theta), HELD, np.array(dtheta), np.array(ddtheta))
    np.testing.assert_allclose(results["tau"], torques, rtol=0, atol=1e-12 * np.abs(torques).max())
    np.testing.assert_allclose(results["M"], six.mass(theta, HELD), rtol=0, atol=1e-15)
    np.testing.assert_allclose(results["N"], six.torques(np.array(theta), HELD, np.zeros(3), np.zeros(3)), rtol=0,
                               atol=1e-14)


@pytest.mark.parametrize("command", [["fk", "0", "0", "0"], ["dynamics", "--theta", "0", "0", "0"],
                                     ["simulate", "--theta0", "0", "0.3", "0.4", "--duration", "0.01"]])
def test_gimbal_angles_for_a_model_without_a_gimbal_are_refused_naming_the_option(cli, command):
    code, out, err = cli(*command, "--gimbal", "0.1", "0.2", "0.3")
    assert (code, out) == (2, "") and err.startswith("phantom-pin: error: --gimbal: the model 'premium_1_5' has no "
                                                     "stylus gimbal"), err


def test_simulate_with_the_gimbal_held_and_its_gravity_compensated_stays_at_rest(cli):
    """simulate --gimbal: the arm under `--controller gravity` (gravity(theta, gimbal), the six-joint
    model's rows) stays at rest when the plant holds the gimbal there too (the arm locked at
    those angles, a second computation): within 1e-12 rad over 0.5 s, without friction or stops.
    Held at locked_at instead, the stylus's load at HELD is missing and the arm moves."""
    theta0 = [0.2, 0.3, 0.5]
    common = ("--model", "touch", "simulate", "--theta0", *theta0, "--duration", "0.5", "--controller", "gravity",
              "--no-friction", "--no-hard-stops")
    code, out, err = cli(*common, "--gimbal", *HELD)
    assert (code, err) == (0, "")
    result = json.loads(out)
    assert result["settings"]["gimbal"] == HELD.tolist()
    assert np.abs(np.array(result["theta"]) - theta0).max() < 1e-12
    with pytest.MonkeyPatch.context() as patch:  # the plant at locked_at, the controller at HELD
        patch.setattr("phantom_pin.device.simulation.held", lambda description, gimbal: description)
        moved = json.loads(cli(*common, "--gimbal", *HELD)[1])
    assert np.abs(np.array(moved["theta"]) - theta0).max() > 1e-3


# -- L12: the model and convention a trajectory or log was written for ----------------------------
def _trajectory(path, record=None, model="touch"):
    """A 2.5 s trajectory at 1 kHz in the report's convention (sines about a posture inside the
    stops, exact derivatives, the model's torques), written here with ``record`` as its second
    line (None: none, as files before 0.5.0)."""
    t = np.arange(2501) / 1000
    w = 2 * np.pi * np.array([0.4, 0.6, 0.5])
    theta = np.array([0.0, 0.3, 0.5]) + 0.1 * np.sin(np.outer(t, w))
    dtheta, ddtheta = 0.1 * w * np.cos(np.outer(t, w)), -0.1 * w**2 * np.sin(np.outer(t, w))
    tau = Phantom.from_model(model).inverse_dynamics(theta, dtheta, ddtheta)
    lines = ["t,theta1,theta2,theta3,dtheta1,dtheta2,dtheta3,ddtheta1,ddtheta2,ddtheta3,tau1,tau2,tau3"]
    lines += [] if record is None else [record]
    lines += [",".join(map(repr, row)) for row in np.column_stack([t, theta, dtheta, ddtheta, tau]).tolist()]
    path.write_text("\n".join(lines) + "\n")
    return path


def test_excite_and_simulate_record_the_model_and_the_convention(tmp_path, cli):
    """L12: the files carried neither. excite's trajectory and simulate's log name the model and
    the convention of their columns on their second line (a # comment, which the readers and
    numpy.loadtxt skip); simulate's log is in the report's convention whatever its input's."""
    code, _, err = cli("--model", "touch", "excite", "-o", tmp_path / "t.csv", "--duration", "5", "--iterations", "1",
                       "--restarts", "1", "--convention", "openhaptics", "-q")
    assert (code, err) == (0, "")
    lines = (tmp_path / "t.csv").read_text().splitlines()
    assert lines[0].startswith("t,theta1,") and lines[1] == "# phantom-pin: model touch, convention openhaptics"
    assert np.loadtxt(tmp_path / "t.csv", delimiter=",", skiprows=1).shape == (5001, 13)
    code, _, err = cli("--model", "touch", "simulate", "--trajectory", tmp_path / "t.csv", "--convention",
                       "openhaptics", "-o", tmp_path / "log.csv", "-q")
    assert (code, err) == (0, "")
    assert (tmp_path / "log.csv").read_text().splitlines()[1] == "# phantom-pin: model touch, convention report"


@pytest.mark.parametrize("given, written", [(("--model", "touch"), ("premium_1_5", "report")),
                                            (("--model", "touch", "--convention", "openhaptics"), ("touch", "report")),
                                            ((), ("touch", "report"))])
def test_a_trajectory_for_another_model_or_convention_is_refused_naming_both(tmp_path, cli, given, written):
    """L12: a trajectory written for another model or convention ran silently. Refused before the
    run in one line naming both, nothing written."""
    path = _trajectory(tmp_path / "t.csv", f"# phantom-pin: model {written[0]}, convention {written[1]}")
    code, out, err = cli("simulate", "--trajectory", path, "-o", tmp_path / "log.csv", *given)
    model = "touch" if "touch" in given else "premium_1_5"
    convention = "openhaptics" if "openhaptics" in given else "report"
    assert (code, out) == (2, "") and err == (
        f"phantom-pin: error: --trajectory: {path} was written for the model {written[0]} in the {written[1]} "
        f"convention, read here for the model {model} in the {convention} convention (give --model and "
        "--convention as written, or delete its '# phantom-pin' line)\n")
    assert not (tmp_path / "log.csv").exists()


def test_a_log_for_another_model_is_refused_by_identify_before_any_fit(tmp_path, cli):
    path = _trajectory(tmp_path / "log.csv", "# phantom-pin: model touch, convention report")
    code, out, err = cli("identify", path, "-o", tmp_path / "id.yaml")
    assert (code, out) == (2, "") and err.startswith(
        f"phantom-pin: error: LOG: {path} was written for the model touch in the report convention, read here for "
        "the model premium_1_5 in the report convention")
    assert not (tmp_path / "id.yaml").exists()


@pytest.mark.parametrize("record", [None, "# phantom-pin: model touch, convention report", "# a comment of one's own"])
def test_a_trajectory_without_the_record_or_with_the_right_one_is_read(tmp_path, cli, record):
    """Files without the record (before 0.5.0, other tools) read as before; so do matching ones:
    the run tracks the trajectory (its start is the file's first state)."""
    path = _trajectory(tmp_path / "t.csv", record)
    code, out, err = cli("--model", "touch", "simulate", "--trajectory", path, "--format", "json", "-q")
    assert (code, err) == (0, "")
    np.testing.assert_allclose(json.loads(out)["theta"][0], [0.0, 0.3, 0.5], rtol=0, atol=1e-15)


def test_a_malformed_record_is_refused(tmp_path, cli):
    path = _trajectory(tmp_path / "t.csv", "# phantom-pin: touch, report")
    code, _, err = cli("--model", "touch", "simulate", "--trajectory", path)
    assert code == 2 and err == (f"phantom-pin: error: --trajectory: {path}: its line '# phantom-pin: touch, report' "
                                 "is not '# phantom-pin: model NAME, convention NAME'\n")
