"""Show a PHANToM in RViz: robot_state_publisher with a committed URDF, joint_state_publisher_gui
for theta1..theta3 (the parallelogram's passive joints follow them through their mimic tags)
and rviz2.

    ros2 launch phantom_description display.launch.py                      # the Premium 1.5
    ros2 launch phantom_description display.launch.py robot:=touch  # the Touch / Omni
    # a Touch whose ROS driver publishes joint_states (waist, shoulder, elbow, yaw, pitch, roll):
    ros2 launch phantom_description display.launch.py robot:=touch convention:=driver gui:=false
    # ... and phantom_pin's node beside it (pip install 'phantom_pin[ros2]'): gravity torques and poses
    ros2 launch phantom_description display.launch.py robot:=touch convention:=driver gui:=false node:=true

``robot`` names a committed URDF of share/phantom_description/urdf (premium_1_5,
premium_1_5_cad, touch). ``convention``: report (joint1..joint6, the report's theta and
the raw gimbal angles) or driver (the drivers' joint names and conventions: urdf/ROBOT_driver.urdf,
committed for the Touch). ``gui``: false leaves joint_states to a running driver. ``node``: true
also runs ``phantom-pin --model MODEL ros2`` (phantom_pin.interfaces.ros2.node: joint_states in; gravity_torque,
gravity_torque_openhaptics, tip_pose, stylus_pose and model_joint_states out).
"""

from pathlib import Path

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, ExecuteProcess, OpaqueFunction
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

#: The robots, each named as its phantom_pin model (`phantom-pin --model`).
ROBOTS = ("premium_1_5", "premium_1_5_cad", "touch")
CONVENTIONS = ("report", "driver")


def _nodes(context):
    robot = LaunchConfiguration("robot").perform(context)
    convention = LaunchConfiguration("convention").perform(context)
    share = Path(get_package_share_directory("phantom_description"))
    urdf = share / "urdf" / (f"{robot}.urdf" if convention == "report" else f"{robot}_driver.urdf")
    if not urdf.is_file():
        raise RuntimeError(f"convention:={convention}: no {urdf.name} for robot:={robot} "
                           f"(the drivers' convention is committed for touch)")
    nodes = [Node(package="robot_state_publisher", executable="robot_state_publisher",
                  parameters=[{"robot_description": urdf.read_text()}])]
    if LaunchConfiguration("gui").perform(context) == "true":
        nodes.append(Node(package="joint_state_publisher_gui", executable="joint_state_publisher_gui"))
    if LaunchConfiguration("node").perform(context) == "true":
        nodes.append(ExecuteProcess(cmd=["phantom-pin", "--model", robot, "ros2"], output="screen"))
    return [*nodes, Node(package="rviz2", executable="rviz2", arguments=["-f", "base_link"])]


def generate_launch_description() -> LaunchDescription:
    return LaunchDescription([
        DeclareLaunchArgument("robot", default_value="premium_1_5", choices=list(ROBOTS),
                              description="the model's URDF in share/phantom_description/urdf"),
        DeclareLaunchArgument("convention", default_value="report", choices=list(CONVENTIONS),
                              description="joint names: report (joint1..) or driver (waist, shoulder, elbow, ...)"),
        DeclareLaunchArgument("gui", default_value="true", choices=["true", "false"],
                              description="start joint_state_publisher_gui (false: a driver publishes joint_states)"),
        DeclareLaunchArgument("node", default_value="false", choices=["true", "false"],
                              description="also run phantom_pin's ROS 2 node (phantom-pin ros2)"),
        OpaqueFunction(function=_nodes),
    ])
