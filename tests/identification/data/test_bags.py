"""Identification from the bags the drivers record (issue 39, 1): rosbag2 files written here with
rosbags' own writer in each effort-publishing driver's shape (its names, signs, elbow and gimbal
conventions transcribed from its source in driver_reference.published; OpenHaptics' joint torques
in mN m: 1000 (-tau1, tau2, tau3), OpenHaptics' reference guide), read back against the log they
were made from, and identified as the same log's CSV is."""

import re

import numpy as np
import pytest
from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.typesys import Stores, get_typestore

from phantom_pin import Phantom, config, describe
from phantom_pin.config import read_overrides
from phantom_pin.config.sampling import random_states
from phantom_pin.exceptions import LogError, MissingDataError
from phantom_pin.identification.data import bags, io
from phantom_pin.interfaces import conventions
from references import driver as driver_reference

TYPES = get_typestore(Stores.ROS2_HUMBLE)
JointState, Header, Time = (TYPES.types[name] for name in ("sensor_msgs/msg/JointState", "std_msgs/msg/Header",
                                                            "builtin_interfaces/msg/Time"))
TOUCH = config.read("touch")
#: The drivers that publish efforts (their profiles' effort_unit), and the rates they publish at (Hz).
EFFORTS = {"sawsensablephantom": 500.0, "geomagic_touch_x_ros2": 200.0}
TOPIC = {"sawsensablephantom": "/arm/measured_js", "geomagic_touch_x_ros2": "/geomagic_touch_x/joint_states"}
EPOCH = 1_764_200_000          # s: stamps of a recent wall clock, as the drivers take them


def exact_log(rate, duration=12.0, seed=1, t=None):
    """An exact log of the Touch at ``rate`` (Hz), or at the times ``t`` (s): five sines per joint
    (0.1-1 Hz, 0.2 rad) about a posture inside the stops, the model's inverse dynamics plus its
    friction law (N m)."""
    t = np.arange(int(duration * rate) + 1) / rate if t is None else t
    rng = np.random.default_rng(seed)
    w, phase = 2 * np.pi * rng.uniform(0.1, 1.0, (3, 5)), rng.uniform(0, 2 * np.pi, (3, 5))
    arg, a = w * t[:, None, None] + phase, 0.2 / 5
    theta = np.array([0.0, 0.3, 0.45]) + a * np.sin(arg).sum(-1)
    dtheta, ddtheta = a * (w * np.cos(arg)).sum(-1), -a * (w**2 * np.sin(arg)).sum(-1)
    law = TOUCH.actuation.friction
    tau = (Phantom.from_model("touch").inverse_dynamics(theta, dtheta, ddtheta) + np.array(law.viscous) * dtheta
           + np.array(law.coulomb) * np.sign(dtheta))
    return io.Log(t, theta, tau)


def messages(driver, log, gimbal=None):
    """(header stamp ns, JointState) per sample of ``log`` as ``driver`` publishes it: OpenHaptics'
    raw angles a = (-theta1, theta2, theta3), the gimbal at ``gimbal`` (default: the model's
    locked posture), efforts 1000 (-tau1, tau2, tau3) mN m (zeros for the gimbal)."""
    gimbal = np.broadcast_to(TOUCH.gimbal.locked_at if gimbal is None else gimbal, log.theta.shape)
    out = []
    for t, theta, tau, g in zip(log.t, log.theta, log.tau, gimbal):
        names, position = driver_reference.published(driver, theta * [-1, 1, 1], g)
        stamp = EPOCH * 10**9 + int(round(t * 1e9))
        header = Header(stamp=Time(sec=stamp // 10**9, nanosec=stamp % 10**9), frame_id="")
        out.append((stamp, JointState(header=header, name=names, position=np.array(position),
                                      velocity=np.array([], float),
                                      effort=np.concatenate([1000 * tau * [-1, 1, 1], np.zeros(3)]))))
    return out


def write_bag(path, streams, storage=StoragePlugin.SQLITE3, latency=None):
    """A rosbag2 recording at ``path``: ``streams`` {topic: [(stamp ns, message)]}, each message
    received ``latency`` ns (an array, per message) after its stamp (default 0.3 ms), written in
    the order received."""
    with Writer(path, version=9, storage_plugin=storage) as writer:
        for topic, stream in streams.items():
            connection = writer.add_connection(topic, JointState.__msgtype__, typestore=TYPES)
            delays = np.full(len(stream), 300_000) if latency is None else latency
            for k in np.argsort([stamp + d for (stamp, _), d in zip(stream, delays)], kind="stable"):
                stamp, message = stream[k]
                writer.write(connection, int(stamp + delays[k]), TYPES.serialize_cdr(message, JointState.__msgtype__))
    return path


@pytest.mark.parametrize("storage", [StoragePlugin.SQLITE3, StoragePlugin.MCAP])
@pytest.mark.parametrize("driver", EFFORTS)
def test_a_drivers_bag_reads_back_as_the_log_it_was_made_from(driver, storage, tmp_path):
    """Each effort-publishing driver's bag, sqlite3 and mcap, recognised from its joint names and
    topic: the header stamps (not the receive times, here 0-12 ms later and out of order), the
    report's theta and N m within rounding (1e-9 s, 1e-12 rad, 1e-12 N m), the gimbal's raw
    angles, the rate stated."""
    log = exact_log(EFFORTS[driver], duration=3.0)
    latency = np.random.default_rng(3).integers(0, 12_000_000, len(log.t))     # up to 12 ms
    path = write_bag(tmp_path / "bag", {TOPIC[driver]: messages(driver, log)}, storage, latency)
    read = bags.read_bag(path)
    assert (read.driver, read.topic, read.messages, read.duplicates) == (driver, TOPIC[driver], len(log.t), 0)
    np.testing.assert_allclose(read.log.t, log.t, rtol=0, atol=1e-9)
    np.testing.assert_allclose(read.log.theta, log.theta, rtol=0, atol=1e-12)
    np.testing.assert_allclose(read.log.tau, log.tau, rtol=0, atol=1e-12)
    np.testing.assert_allclose(read.gimbal, np.broadcast_to(TOUCH.gimbal.locked_at, (len(log.t), 3)), atol=1e-12)
    assert read.reordered and not read.resampled       # recorded in the order received, not stamped
    assert read.lines()[0] == (f"{TOPIC[driver]} ({driver}): {len(log.t)} messages over 3.000 s at "
                               f"{EFFORTS[driver]:g} Hz (header stamps); stamps out of order, sorted")


#: How far apart the link numbers of one log identified twice may be, each relative to its link's
#: size (link_differences): the projection's end (physical.GAP) leaves them 7e-10 (OpenHaptics'
#: CSV) and 6e-8 (a bag, read back within 1e-9 s and 1e-12 rad) apart from the report's CSV
#: (issue 42, L14: 0.3 % and 16 % with the barrier stopped at a duality gap of 1e-7, measured).
LINKS_AGREE = 1e-6
#: identify's options for these logs: no delay to estimate, no gains to correct (exact torques).
FAST = ("--delay", "0", "--fixed-gains")


def link_differences(one, other):
    """{key: the difference} of the link numbers (links.<link>.mass, .com.*, .inertia.*) of two
    overlays, each relative to its link's size in ``one``: a mass to the mass, a centre of mass
    coordinate to the link's radius of gyration (sqrt(largest inertia entry / mass)), an inertia
    entry to the link's largest."""
    out = {}
    for key in (k for k in one if k.startswith("links.")):
        link, kind = key.split(".")[1:3]
        inertia = max(abs(v) for k, v in one.items() if k.startswith(f"links.{link}.inertia."))
        mass = one[f"links.{link}.mass"]
        size = {"mass": mass, "com": np.sqrt(inertia / mass), "inertia": inertia}[kind]
        out[key] = abs(other[key] - one[key]) / size
    return out


@pytest.fixture(scope="module")
def report_csv(tmp_path_factory):
    """(the sawSensablePhantom rate's exact log, the overlay identify writes from it as a CSV in
    the report's convention): the reference both conventions' tests compare with."""
    from phantom_pin.cli import main

    where = tmp_path_factory.mktemp("report_csv")
    log = exact_log(EFFORTS["sawsensablephantom"])
    io.write_log(where / "log.csv", log.t, log.theta, log.tau)
    assert main(["--model", "touch", "identify", str(where / "log.csv"), "-o", str(where / "csv.yaml"), *FAST]) == 0
    return log, read_overrides(where / "csv.yaml")


def test_a_sawsensablephantom_bag_identifies_as_its_csv_does(tmp_path, cli, report_csv):
    """identify BAG (sawSensablePhantom's measured_js at 500 Hz, sqlite3) writes the model that
    identify writes from the same samples as a CSV in the report's convention: the same keys
    plus the stylus posture it was held at, the friction within 1e-9 relative (the bag's mN m
    round trip), every link number within LINKS_AGREE of the link's size, even those the data
    cannot see (issue 42's L14), and the same torques at 200 seeded states within 1e-9 of their
    RMS."""
    log, from_csv = report_csv
    path = write_bag(tmp_path / "bag", {TOPIC["sawsensablephantom"]: messages("sawsensablephantom", log)})
    code, out, err = cli("--model", "touch", "identify", path, "-o", tmp_path / "bag.yaml", *FAST)
    assert code == 0, err
    assert out.splitlines()[0].startswith("/arm/measured_js (sawsensablephantom): 6001 messages over 12.000 s at "
                                          "500 Hz")
    from_bag = read_overrides(tmp_path / "bag.yaml")
    stylus = {f"gimbal.locked_at.{k}": a for k, a in enumerate(TOUCH.gimbal.locked_at)}
    assert set(from_bag) == set(from_csv) | set(stylus)
    for key in (k for k in from_csv if "friction" in k):
        assert from_bag[key] == pytest.approx(from_csv[key], rel=1e-9, abs=1e-15), key
    assert {k: from_bag[k] for k in stylus} == pytest.approx(stylus, abs=1e-12)
    apart = link_differences(from_csv, from_bag)
    assert max(apart.values()) < LINKS_AGREE, max(apart.items(), key=lambda item: item[1])
    states = random_states(TOUCH.limits, 200, 3)
    bag, csv = (Phantom(describe("touch", overrides=o)).inverse_dynamics(*states) for o in (from_bag, from_csv))
    assert np.abs(bag - csv).max() < 1e-9 * np.sqrt((csv**2).mean())


def test_a_log_in_openhaptics_convention_identifies_as_in_the_reports(tmp_path, cli, report_csv):
    """identify --convention openhaptics of the same samples as OpenHaptics' joint angles and mN m
    torques (conventions.openhaptics_from_theta, openhaptics_torque_from_tau; read back within
    rounding, not bit for bit) writes the report convention's overlay: the same keys, every link
    number within LINKS_AGREE of its link's size (issue 42's L14: those the data cannot see
    too), the friction within 1e-9 relative."""
    log, from_csv = report_csv
    angles, torques = conventions.openhaptics_from_theta(log.theta), conventions.openhaptics_torque_from_tau(log.tau)
    io.write_log(tmp_path / "openhaptics.csv", log.t, angles, torques)
    read = io.read_log(tmp_path / "openhaptics.csv", "openhaptics")
    assert np.abs(read.tau - log.tau).max() < 1e-15 and (read.tau != log.tau).any()     # rounding apart
    code, _, err = cli("--model", "touch", "identify", tmp_path / "openhaptics.csv", "--convention", "openhaptics",
                       "-o", tmp_path / "openhaptics.yaml", *FAST)
    assert code == 0, err
    from_openhaptics = read_overrides(tmp_path / "openhaptics.yaml")
    assert set(from_openhaptics) == set(from_csv)
    apart = link_differences(from_csv, from_openhaptics)
    assert len(apart) == 5 * 10 and max(apart.values()) < LINKS_AGREE, max(apart.items(), key=lambda item: item[1])
    for key in (k for k in from_csv if "friction" in k):
        assert from_openhaptics[key] == pytest.approx(from_csv[key], rel=1e-9, abs=1e-15), key


def _stream(driver="sawsensablephantom", duration=3.0):
    return messages(driver, exact_log(EFFORTS[driver], duration=duration))


def test_stamps_out_of_order_and_messages_recorded_twice_are_handled(tmp_path):
    """A bag whose messages arrive out of stamp order (sorted: the log is the original) and with
    some recorded twice (dropped, counted)."""
    stream = _stream()
    shuffled = stream[:]
    shuffled[100], shuffled[101] = shuffled[101], shuffled[100]
    twice = shuffled + shuffled[200:205]
    path = write_bag(tmp_path / "bag", {TOPIC["sawsensablephantom"]: twice},
                     latency=np.zeros(len(twice), int) + np.r_[np.zeros(len(shuffled), int), np.arange(5) + 1])
    read = bags.read_bag(path)
    assert read.duplicates == 5 and read.messages == len(twice)
    np.testing.assert_allclose(read.log.t, np.arange(len(stream)) / 500.0, atol=1e-9)
    assert "5 message(s) recorded twice dropped" in read.lines()[0]


def test_jittered_stamps_are_resampled_onto_their_mean_rate(tmp_path):
    """Stamps with 0.3 ms of jitter on 2 ms (15 %, beyond io.RATE_TOLERANCE) are resampled onto a
    uniform grid at the mean rate by linear interpolation: the angles there agree with the exact
    motion to the interpolation's error (under 1e-5 rad for sines below 1 Hz)."""
    driver, rate = "sawsensablephantom", EFFORTS["sawsensablephantom"]
    log = exact_log(rate, duration=3.0)
    jitter = np.random.default_rng(5).uniform(-3e-4, 3e-4, len(log.t))
    jitter[[0, -1]] = 0
    shaken = exact_log(rate, t=log.t + jitter)            # the motion at the jittered stamps
    read = bags.read_bag(write_bag(tmp_path / "bag", {TOPIC[driver]: messages(driver, shaken)}))
    assert read.resampled and "resampled onto a uniform 500 Hz grid" in read.lines()[0]
    np.testing.assert_allclose(read.log.t, log.t, atol=1e-9)
    assert np.abs(read.log.theta - log.theta).max() < 1e-5


@pytest.mark.parametrize("case, message", [
    ("gap", "a gap of 52 ms after 1.000 s in a stream at 500 Hz (messages lost)"),
    ("one stamp, two messages", "two different messages stamped"),
    ("no efforts", "geomagic_touch_ros2 publishes no efforts on /phantom/joint_states"),
    ("two topics", "holds 2 sensor_msgs/msg/JointState topics (/arm/measured_js, /other/measured_js)"),
    ("unknown names", "joints a, b, c, d, e, f are no driver profile's: name the driver"),
    ("not a bag", "not a readable rosbag2 recording (A metadata key is missing"),
])
def test_a_bag_that_is_no_log_is_refused_in_one_line(case, message, tmp_path, cli):
    """Each defect refused by the command line in one line saying what is wrong, nothing written."""
    stream = _stream()
    streams = {TOPIC["sawsensablephantom"]: stream}
    if case == "gap":
        streams = {TOPIC["sawsensablephantom"]: stream[:501] + stream[526:]}
    elif case == "one stamp, two messages":
        stamp, message_ = stream[10]
        changed = JointState(header=message_.header, name=message_.name, position=message_.position + 0.01,
                             velocity=message_.velocity, effort=message_.effort)
        streams = {TOPIC["sawsensablephantom"]: stream + [(stamp, changed)]}
    elif case == "no efforts":
        streams = {"/phantom/joint_states": messages("geomagic_touch_ros2", exact_log(500.0, duration=3.0))}
    elif case == "two topics":
        streams = {TOPIC["sawsensablephantom"]: stream, "/other/measured_js": stream}
    elif case == "unknown names":
        streams = {"/js": [(s, JointState(header=m.header, name=list("abcdef"), position=m.position,
                                          velocity=m.velocity, effort=m.effort)) for s, m in stream]}
    path = write_bag(tmp_path / "bag", streams)
    if case == "not a bag":
        (path / "metadata.yaml").write_text("x: 1\n")
    code, out, err = cli("--model", "touch", "identify", path, "-o", tmp_path / "id.yaml")
    assert code == 2 and err.count("\n") == 1 and message in err, err
    assert not (tmp_path / "id.yaml").exists()


def test_the_topic_and_driver_choose_where_the_bag_is_ambiguous(tmp_path):
    """--topic picks one of two JointState topics; --driver names the profile of unknown joint
    names' topic only where it holds that profile's names (else LogError naming driver)."""
    stream = _stream()
    path = write_bag(tmp_path / "bag", {TOPIC["sawsensablephantom"]: stream, "/other/measured_js": stream})
    assert bags.read_bag(path, driver="sawsensablephantom", topic="/other/measured_js").topic == "/other/measured_js"
    with pytest.raises(LogError, match="/nothing is not a sensor_msgs/msg/JointState topic") as error:
        bags.read_bag(path, topic="/nothing")
    assert error.value.argument == "topic"
    with pytest.raises(LogError, match="not geomagic_touch_x_ros2's") as error:
        bags.read_bag(path, driver="geomagic_touch_x_ros2", topic="/other/measured_js")
    assert error.value.argument == "driver"
    with pytest.raises(MissingDataError, match="publishes no efforts"):
        bags.read_bag(path, driver="geomagic_touch_ros2", topic="/other/measured_js")


def test_a_stylus_that_swings_is_refused_and_a_held_one_carried_where_it_was(tmp_path, cli):
    """The Touch's stylus load is modelled locked: a bag whose gimbal swings 0.3 rad is refused
    naming the gimbal angle; one held 0.2 rad off the model's posture is identified with the
    stylus there (its overlay carries the posture)."""
    driver, log = "sawsensablephantom", exact_log(500.0, duration=6.0)
    swing = np.asarray(TOUCH.gimbal.locked_at) + np.outer(0.3 * np.sin(log.t), [1, 0, 0])
    path = write_bag(tmp_path / "swing", {TOPIC[driver]: messages(driver, log, swing)})
    code, _, err = cli("--model", "touch", "identify", path, "-o", tmp_path / "id.yaml")
    assert code == 2 and re.search(r"gimbal angle 1 swings 0\.3\d* rad about its median", err), err
    held = np.asarray(TOUCH.gimbal.locked_at) + [0.0, 0.2, 0.0]
    path = write_bag(tmp_path / "held", {TOPIC[driver]: messages(driver, log, held)})
    code, _, err = cli("--model", "touch", "identify", path, "-o", tmp_path / "id.yaml", "--delay", "0",
                       "--fixed-gains", "--accept")
    assert code == 0, err
    overlay = read_overrides(tmp_path / "id.yaml")
    assert [overlay[f"gimbal.locked_at.{k}"] for k in range(3)] == pytest.approx(held.tolist(), abs=1e-12)


def test_a_csv_log_with_driver_options_is_refused(tmp_path, cli):
    """--driver and --topic read bags: given with a CSV log, refused naming the option."""
    log = exact_log(500.0, duration=3.0)
    io.write_log(tmp_path / "log.csv", log.t, log.theta, log.tau)
    code, _, err = cli("--model", "touch", "identify", tmp_path / "log.csv", "-o", tmp_path / "id.yaml",
                       "--driver", "sawsensablephantom")
    assert code == 2 and "--driver" in err and "is a CSV log, not a rosbag2 recording" in err, err
