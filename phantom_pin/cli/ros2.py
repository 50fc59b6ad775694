"""``phantom-pin ros2`` (the node of phantom_pin.interfaces.ros2.node) and ``phantom-pin sim-driver`` (a
simulated driver, phantom_pin.interfaces.ros2.simulated_driver): the ``ros2`` extra."""

from __future__ import annotations

import argparse
import dataclasses
import math

from phantom_pin.cli.common import description
from phantom_pin.description.build import held
from phantom_pin.dynamics.phantom import Phantom
from phantom_pin.exceptions import MissingDataError, PhantomPinError
from phantom_pin.interfaces import profiles

#: --compensate's choices and the terms each compensates.
COMPENSATE = {"gravity": ("gravity",), "gravity,friction": ("gravity", "friction"),
              "gravity,friction,inertia": ("gravity", "friction", "inertia"), "none": ()}
#: --kappa's default with inertia compensated: the share docs/feel.md measures (2.2 times less mass felt).
KAPPA = 0.6


def _topics(items: list[str]) -> dict[str, str]:
    """--topic ROLE=NAME items as a mapping; PhantomPinError naming --topic otherwise (an
    unknown role, a role given twice, two roles on one topic)."""
    from phantom_pin.interfaces.ros2.node import TOPICS

    topics: dict[str, str] = {}
    for item in items:
        role, _, name = item.partition("=")
        if role not in TOPICS or not name.strip() or " " in name:
            raise PhantomPinError(f"expected ROLE=NAME with ROLE one of {', '.join(TOPICS)}, got {item!r}",
                                  argument="--topic")
        if role in topics:
            raise PhantomPinError(f"{role} given twice; give it once", argument="--topic")
        topics[role] = name
    names = {**TOPICS, **topics}
    shared = sorted({n for n in names.values() if list(names.values()).count(n) > 1})
    if shared:
        roles = [r for r, n in names.items() if n == shared[0]]
        raise PhantomPinError(f"{' and '.join(roles)} on one topic {shared[0]!r}: give each its own",
                              argument="--topic")
    return topics


def _rclpy() -> None:
    try:
        import rclpy  # noqa: F401  (the ros2 extra)
    except ImportError:
        raise MissingDataError("ros2: rclpy is not installed (pip install 'phantom_pin[ros2]')") from None


def _max_force(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not value > 0:  # NaN too; inf: no limit of one's own
        raise argparse.ArgumentTypeError(f"expected a force > 0 N (inf for none), got {text!r}")
    return value


def ros2(args: argparse.Namespace) -> int:
    """Check everything the node needs, then spin it until SIGINT or SIGTERM."""
    _rclpy()
    from phantom_pin.interfaces.ros2 import node

    topics = _topics(args.topic)
    robot = Phantom(description(args, prefix=args.prefix))  # refused before ROS starts
    driver = None
    if args.driver is not None:
        profile = profiles.load(args.driver)
        if args.relay:
            profile = profiles.relayed(profile)
        if robot.config.gimbal is None:
            raise PhantomPinError(f"the drivers' profiles are the Touch's; {robot.config.name} has no stylus gimbal "
                                  "(use --model touch)", argument="--driver")
        node.message_type(profile.force.type)  # installed, else one line
        terms = COMPENSATE[args.compensate]
        kappa = (KAPPA if args.kappa is None else args.kappa) if "inertia" in terms else 0.0
        if args.kappa is not None and "inertia" not in terms:
            raise PhantomPinError("goes with --compensate gravity,friction,inertia", argument="--kappa")
        driver = node.DriverBridge(robot, profile, terms, args.max_force, kappa=kappa)
    elif args.compensate != "gravity" or not math.isinf(args.max_force) or args.relay or args.kappa is not None:
        raise PhantomPinError("goes with --driver (the force command of a driver)",
                              argument="--relay" if args.relay else "--compensate" if args.compensate != "gravity"
                              else "--kappa" if args.kappa is not None else "--max-force")
    node.Bridge(robot)
    return node.spin(robot, topics, driver)


def sim_driver(args: argparse.Namespace) -> int:
    """Check everything the simulated driver needs, then run it until SIGINT or SIGTERM."""
    _rclpy()
    from phantom_pin.device.device import Device
    from phantom_pin.interfaces.ros2 import simulated_driver as simulated
    from phantom_pin.interfaces.ros2.node import message_type

    profile = profiles.load(args.driver)
    made = description(args, prefix=args.prefix)
    gimbal = made.config.gimbal
    if gimbal is None:
        raise PhantomPinError(f"the drivers' profiles are the Touch's; {made.config.name} has no stylus gimbal "
                              "(use --model touch)", argument="--driver")
    angles = gimbal.locked_at if args.gimbal is None else tuple(args.gimbal)
    outside = [k for k, (a, lo, hi) in enumerate(zip(angles, gimbal.lower, gimbal.upper)) if not lo <= a <= hi]
    if outside or not all(math.isfinite(a) for a in angles):
        raise PhantomPinError(f"expected three angles (rad) inside the gimbal's ranges {list(gimbal.lower)} .. "
                              f"{list(gimbal.upper)}, got {list(angles)}", argument="--gimbal")
    if args.rate is not None:
        if not 0 < args.rate <= 10000:
            raise PhantomPinError(f"expected a rate in (0, 10000] Hz, got {args.rate!r}", argument="--rate")
        profile = dataclasses.replace(profile, joint_states=dataclasses.replace(profile.joint_states, rate=args.rate))
    device = Device(Phantom(held(made, angles)))    # the plant carries the stylus there
    theta0 = args.theta0 if args.theta0 is not None else (0.0, 0.5, 0.6)
    message_type(profile.force.type)
    simulation = simulated.DriverSimulation(device, profile, theta0, args.hold)
    return simulated.spin(simulation, angles, args.prefix)


def add_parsers(sub: argparse._SubParsersAction) -> None:
    """ros2, sim-driver."""
    command = sub.add_parser("ros2", help="a ROS 2 node: the drivers' joint_states in; gravity torques, the tip's "
                                          "and the stylus's poses and the model's joint states out; with --driver, "
                                          "that driver's force command (gravity compensated, plus a user's wrench)")
    command.add_argument("--prefix", default="", help="the joint and frame names' prefix (default none)")
    command.add_argument("--topic", action="append", default=[], metavar="ROLE=NAME",
                         help="rename a topic: joint_states, wrench, gravity_torque, gravity_torque_openhaptics, "
                              "tip_pose, stylus_pose, model_joint_states (repeatable)")
    command.add_argument("--driver", choices=profiles.names(), metavar="PROFILE",
                         help=f"speak this driver's topics and force command: {', '.join(profiles.names())}")
    command.add_argument("--compensate", choices=tuple(COMPENSATE), default="gravity",
                         help="what the force compensates (default gravity; friction: the model's law at a filtered "
                              "rate)")
    command.add_argument("--kappa", type=float, metavar="K",
                         help=f"with inertia compensated: the share of M ddtheta + C dtheta (0 < K < 1; {KAPPA})")
    command.add_argument("--max-force", type=_max_force, default=math.inf, metavar="N",
                         help="the largest force sent (N; also the driver's clamp and the motors' limits)")
    command.add_argument("--relay", action="store_true",
                         help="send the force as geometry_msgs/Vector3 on the driver's force topic + _relay, for the "
                              "one-file relay of docs/drivers.md (a driver whose message type is not on PyPI)")
    command.set_defaults(run=ros2, options={"prefix": "--prefix", "topics": "--topic", "driver": "--driver",
                                            "compensate": "--compensate", "max_force": "--max-force",
                                            "kappa": "--kappa"})
    simulated = sub.add_parser("sim-driver", help="a simulated driver: the device's plant under a driver's force "
                                                  "command, its joint states published in real time (ROS 2)")
    simulated.add_argument("--driver", required=True, choices=profiles.names(), metavar="PROFILE",
                           help=f"the driver to simulate: {', '.join(profiles.names())}")
    simulated.add_argument("--theta0", type=float, nargs=3, metavar=("T1", "T2", "T3"),
                           help="the start (rad, the report's theta; default 0 0.5 0.6)")
    simulated.add_argument("--gimbal", type=float, nargs=3, metavar=("G1", "G2", "G3"),
                           help="the stylus's raw gimbal angles, held (rad; default the model's locked_at)")
    simulated.add_argument("--hold", type=float, default=0.0, metavar="S",
                           help="hold the stylus at theta0 for the first S seconds, or until the process gets SIGUSR1, "
                                "then let go (default 0)")
    simulated.add_argument("--rate", type=float, metavar="HZ",
                           help="the joint states' rate (Hz; default the driver's)")
    simulated.add_argument("--prefix", default="", help="the joint names' prefix (default none)")
    simulated.set_defaults(run=sim_driver, options={"theta0": "--theta0", "hold": "--hold", "driver": "--driver",
                                                    "gimbal": "--gimbal", "rate": "--rate"})
