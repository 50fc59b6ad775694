"""Show a PHANToM in RViz: robot_state_publisher with a committed URDF, joint_state_publisher_gui
for theta1..theta3 (the parallelogram's passive joints follow them through their mimic tags)
and rviz2.

    ros2 launch phantom_description display.launch.py                      # the Premium 1.5
    ros2 launch phantom_description display.launch.py robot:=phantom_touch  # the Touch / Omni

``robot`` names a committed URDF of share/phantom_description/urdf (phantom_1_5,
phantom_1_5_cad, phantom_touch).
"""

from pathlib import Path

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, OpaqueFunction
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

ROBOTS = ("phantom_1_5", "phantom_1_5_cad", "phantom_touch")


def _nodes(context):
    robot = LaunchConfiguration("robot").perform(context)
    share = Path(get_package_share_directory("phantom_description"))
    robot_description = (share / "urdf" / f"{robot}.urdf").read_text()
    return [
        Node(package="robot_state_publisher", executable="robot_state_publisher",
             parameters=[{"robot_description": robot_description}]),
        Node(package="joint_state_publisher_gui", executable="joint_state_publisher_gui"),
        Node(package="rviz2", executable="rviz2", arguments=["-f", "base_link"]),
    ]


def generate_launch_description() -> LaunchDescription:
    return LaunchDescription([
        DeclareLaunchArgument("robot", default_value="phantom_1_5", choices=list(ROBOTS),
                              description="the model's URDF in share/phantom_description/urdf"),
        OpaqueFunction(function=_nodes),
    ])
