"""Show the PHANToM Premium 1.5 in RViz: robot_state_publisher with the committed URDF,
joint_state_publisher_gui for theta1..theta3 (the parallelogram's passive joints follow
them through their mimic tags) and rviz2.

    ros2 launch phantom_description display.launch.py
"""

from pathlib import Path

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch_ros.actions import Node


def generate_launch_description() -> LaunchDescription:
    share = Path(get_package_share_directory("phantom_description"))
    robot_description = (share / "urdf" / "phantom_1_5.urdf").read_text()
    return LaunchDescription([
        Node(package="robot_state_publisher", executable="robot_state_publisher",
             parameters=[{"robot_description": robot_description}]),
        Node(package="joint_state_publisher_gui", executable="joint_state_publisher_gui"),
        Node(package="rviz2", executable="rviz2", arguments=["-f", "base_link"]),
    ])
