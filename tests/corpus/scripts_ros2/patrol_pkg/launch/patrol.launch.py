# Course pattern: an ament_python package's launch file - use_sim_time, a YAML file for every
# node (/**), a launch argument passed on, a remapping.
import os

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node


def generate_launch_description():
    pkg_share = get_package_share_directory("patrol_pkg")
    params = os.path.join(pkg_share, "config", "patrol.yaml")
    use_sim_time = LaunchConfiguration("use_sim_time", default="true")
    leg_length = LaunchConfiguration("leg_length")
    return LaunchDescription(
        [
            DeclareLaunchArgument("leg_length", default_value="0.4"),
            Node(
                package="patrol_pkg",
                executable="patrol",
                parameters=[params, {"use_sim_time": use_sim_time, "leg_length": leg_length}],
                output="screen",
            ),
            Node(
                package="patrol_pkg",
                executable="odom_logger",
                name="odom_logger",
                parameters=[params, {"use_sim_time": use_sim_time}],
                remappings=[("wheel_odom", "odom")],
                output="screen",
            ),
        ]
    )
