# Course pattern: a ROS 2 Python launch file - a launch argument, two nodes, parameters from a
# YAML file and from a dict, remappings, a namespace.
import os

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node


def generate_launch_description():
    params_file = os.path.join(
        get_package_share_directory("corpus2"), "config", "approach_params.yaml"
    )
    stop_distance = LaunchConfiguration("stop_distance")

    return LaunchDescription(
        [
            DeclareLaunchArgument(
                "stop_distance", default_value="0.3", description="where the driver stops [m]"
            ),
            Node(
                package="corpus2",
                executable="launch_driver",
                name="driver",
                output="screen",
                parameters=[params_file, {"stop_distance": stop_distance}],
                remappings=[("cmd_vel", "Control"), ("range", "Distance")],
            ),
            Node(
                package="corpus2",
                executable="range_monitor",
                name="range_monitor",
                namespace="monitor",
                output="screen",
                parameters=[{"threshold_cm": 40}],
                remappings=[("range", "/Distance")],
            ),
        ]
    )
