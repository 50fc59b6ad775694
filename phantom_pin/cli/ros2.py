"""``phantom-pin ros2``: the ROS 2 node of phantom_pin.ros2 (the ``ros2`` extra)."""

from __future__ import annotations

import argparse

from phantom_pin.cli.common import description
from phantom_pin.dynamics.model import Phantom
from phantom_pin.exceptions import MissingDataError, PhantomPinError


def _topics(items: list[str]) -> dict[str, str]:
    """--topic ROLE=NAME items as a mapping; PhantomPinError naming --topic otherwise."""
    from phantom_pin.ros2 import TOPICS

    topics = {}
    for item in items:
        role, _, name = item.partition("=")
        if role not in TOPICS or not name.strip() or " " in name:
            raise PhantomPinError(f"expected ROLE=NAME with ROLE one of {', '.join(TOPICS)}, got {item!r}",
                                  argument="--topic")
        topics[role] = name
    return topics


def ros2(args: argparse.Namespace) -> int:
    """Check everything the node needs, then spin it until SIGINT or SIGTERM."""
    try:
        import rclpy  # noqa: F401  (the ros2 extra)
    except ImportError:
        raise MissingDataError("ros2: rclpy is not installed (pip install 'phantom_pin[ros2]')") from None
    from phantom_pin import ros2 as node

    topics = _topics(args.topic)
    robot = Phantom(description(args, prefix=args.prefix))  # refused before ROS starts
    node.Bridge(robot)
    return node.spin(robot, topics)


def add_parsers(sub: argparse._SubParsersAction) -> None:
    """ros2."""
    command = sub.add_parser("ros2", help="a ROS 2 node: the drivers' joint_states in; gravity torques, the tip's "
                                          "and the stylus's poses and the model's joint states out")
    command.add_argument("--prefix", default="", help="the joint and frame names' prefix (default none)")
    command.add_argument("--topic", action="append", default=[], metavar="ROLE=NAME",
                         help="rename a topic: joint_states, gravity_torque, gravity_torque_openhaptics, "
                              "tip_pose, stylus_pose, model_joint_states (repeatable)")
    command.set_defaults(run=ros2, options={"prefix": "--prefix", "topics": "--topic"})
