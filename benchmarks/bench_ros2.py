"""The node's servo path over ROS 2 on loopback: a driver's joint states replayed at 1 kHz (a
separate process, as a driver is), the node (`phantom-pin --model touch ros2 --driver P`)
answering each with the driver's force command; the share answered and the latency (the
command's receipt minus its state's stamp, the system clock) at the median and the 99th
percentile. The same replay against an echo node (rclpy, no computation: the transport's
floor) in the same run gives the ratio.

    python benchmarks/bench_ros2.py [--driver sawsensablephantom] [--seconds 5] [--rate 1000]
"""

from __future__ import annotations

import argparse
import os
import platform
import subprocess
import sys
import time

import numpy as np

from phantom_pin.interfaces import profiles

ECHO = """
import sys, rclpy
from rclpy.qos import QoSProfile, ReliabilityPolicy
from sensor_msgs.msg import JointState
from geometry_msgs.msg import WrenchStamped
rclpy.init()
node = rclpy.create_node("echo")
out = node.create_publisher(WrenchStamped, sys.argv[2],
                            QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE))
def answer(message):
    command = WrenchStamped()
    command.header.stamp = message.header.stamp
    out.publish(command)
node.create_subscription(JointState, sys.argv[1], answer,
                         QoSProfile(depth=10, reliability=ReliabilityPolicy.BEST_EFFORT))
print("echo ready", file=sys.stderr, flush=True)
rclpy.spin(node)
"""

REPLAY = """
import sys, time, json, rclpy
from rclpy.qos import QoSProfile, ReliabilityPolicy
from rclpy.executors import SingleThreadedExecutor
from sensor_msgs.msg import JointState
from geometry_msgs.msg import WrenchStamped
topic, out_topic, seconds, rate, names, positions = sys.argv[1], sys.argv[2], float(sys.argv[3]), float(sys.argv[4]), \
    sys.argv[5].split(","), [float(v) for v in sys.argv[6].split(",")]
rclpy.init()
node = rclpy.create_node("replay")
states = node.create_publisher(JointState, topic, QoSProfile(depth=10, reliability=ReliabilityPolicy.BEST_EFFORT))
latencies = []
def received(message):
    stamp = message.header.stamp
    latencies.append((time.time_ns() - (stamp.sec * 10**9 + stamp.nanosec)) * 1e-9)
qos = QoSProfile(depth=1000, reliability=ReliabilityPolicy.BEST_EFFORT)
node.create_subscription(WrenchStamped, out_topic, received, qos)
executor = SingleThreadedExecutor()
executor.add_node(node)
deadline = time.monotonic() + 60
while node.count_subscribers(topic) < 1 or node.count_publishers(out_topic) < 1:
    assert time.monotonic() < deadline, "no node"
    executor.spin_once(timeout_sec=0.05)
end = time.monotonic() + 1.0
while time.monotonic() < end:
    executor.spin_once(timeout_sec=0.05)
count = int(seconds * rate)
start = time.monotonic()
for k in range(count):
    message = JointState()
    message.header.stamp.sec, message.header.stamp.nanosec = divmod(time.time_ns(), 10**9)
    message.name, message.position = names, positions
    states.publish(message)
    while True:
        left = start + (k + 1) / rate - time.monotonic()
        if left <= 0:
            break
        executor.spin_once(timeout_sec=left)
end = time.monotonic() + 1.0
while time.monotonic() < end:
    executor.spin_once(timeout_sec=0.01)
print(json.dumps({"sent": count, "latencies": latencies}))
"""


def measure(command: list[str], topic: str, out_topic: str, names: list[str], positions: list[float],
            seconds: float, rate: float, env: dict[str, str]) -> dict:
    """Start ``command`` (a node), wait for its ready line, replay, stop it: the replay's figures."""
    import json

    node = subprocess.Popen(command, env=env, stderr=subprocess.PIPE, text=True)
    try:
        while "ready" not in (line := node.stderr.readline()) and "->" not in line:
            if node.poll() is not None:
                raise SystemExit(f"the node stopped: {node.stderr.read()}")
        result = subprocess.run([sys.executable, "-c", REPLAY, topic, out_topic, str(seconds), str(rate),
                                 ",".join(names), ",".join(map(str, positions))], env=env, capture_output=True,
                                text=True, timeout=120 + seconds)
        if result.returncode:
            raise SystemExit(result.stderr)
        return json.loads(result.stdout)
    finally:
        node.terminate()
        node.wait(timeout=20)


def summary(figures: dict) -> tuple[float, float, float]:
    """(share answered, median latency ms, 99th percentile ms)."""
    latencies = np.array(figures["latencies"]) * 1e3
    return len(latencies) / figures["sent"], float(np.median(latencies)), float(np.percentile(latencies, 99))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--driver", default="sawsensablephantom", choices=[
        n for n in profiles.names() if profiles.load(n).force.type.endswith("WrenchStamped")])
    parser.add_argument("--seconds", type=float, default=5.0)
    parser.add_argument("--rate", type=float, default=1000.0)
    args = parser.parse_args()
    profile = profiles.load(args.driver)
    env = {**os.environ, "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST", "ROS_DOMAIN_ID": str(1 + os.getpid() % 100),
           "PYTHONUNBUFFERED": "1"}
    theta = np.array([0.2, 0.6, 0.5])
    positions = [*profile.state_from_arm(theta), *profile.state_from_gimbal(np.zeros(3))]
    topic, out_topic = profile.joint_states.topic, profile.force.topic
    names = list(profile.joint_states.names)
    print(f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores; {args.seconds:g} s at "
          f"{args.rate:g} Hz, {args.driver}")
    echo = summary(measure([sys.executable, "-c", ECHO, topic, out_topic], topic, out_topic, names, positions,
                           args.seconds, args.rate, env))
    node = summary(measure([sys.executable, "-m", "phantom_pin.cli", "--model", "touch", "ros2", "--driver",
                            args.driver], topic, out_topic, names, positions, args.seconds, args.rate, env))
    for label, (share, median, p99) in (("echo (rclpy, no computation)", echo), ("phantom-pin ros2 --driver", node)):
        print(f"{label:32s} answered {100 * share:6.2f} %, latency median {median:.3f} ms, 99th percentile "
              f"{p99:.3f} ms")
    print(f"ratio node / echo: median {node[1] / echo[1]:.2f}, 99th percentile {node[2] / echo[2]:.2f}")
    time.sleep(0)


if __name__ == "__main__":
    main()
