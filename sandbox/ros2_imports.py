"""Sentences for modules a ROS 2 node cannot import here, instead of "No module named ...".

The ROS 2 twin of sandbox/ros_imports.py: a finder appended to the end of ``sys.meta_path``
answers only after every other finder has failed, and only for the names below (plus any
``*_msgs``/``*_srvs``/``*_interfaces`` package, and a submodule missing from a package we have).
ROS 1 modules (rospy, roslib, tf, actionlib...) say that this run is ROS 2 and what the ROS 2
form is; ROS 2 libraries RoboDojo lacks say what to use instead.

Which interface packages exist is read from sandbox/ros_compat2 itself (a package directory
with a ``msg``, ``srv`` or ``action`` module), so this list never disagrees with what imports.
"""

from __future__ import annotations

import functools
import os
import sys
from collections.abc import Sequence
from types import ModuleType

ROS_COMPAT2_DIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "ros_compat2")
_INTERFACE_KINDS = ("msg", "srv", "action")

_ROS1 = (
    "is part of ROS 1 and this run is ROS 2 (a node that imports rclpy makes the run ROS 2, "
    "and a run is one or the other)"
)
_CLI_TOOL = "a command-line tool, not a library a node can use"

# Top-level module -> what to use instead (the sentence ends the error message).
MISSING_MODULES: dict[str, str] = {
    "rospy": (
        f"{_ROS1}; write this node with rclpy (rclpy.init(), a Node, rclpy.spin), or every "
        "node of the run with rospy"
    ),
    "roslib": f"{_ROS1}; ROS 2 needs no load_manifest: import the message packages directly",
    "tf": (
        f"{_ROS1}; use tf_transformations (euler_from_quaternion, quaternion_from_euler) and "
        "tf2_ros (Buffer, TransformListener)"
    ),
    "actionlib": f"{_ROS1}; use rclpy.action (ActionServer, ActionClient)",
    "rosbag": (
        "nodes cannot read or write bag files; every run is recorded, and its recording "
        "downloads as MCAP from the run's page"
    ),
    "rosgraph": f"{_ROS1}; node.get_topic_names_and_types() lists the run's topics",
    "genpy": f"{_ROS1}; messages come from <package>.msg, times from rclpy.time",
    "launch": (
        "a launch file is given to the run (robodojo run --launch FILE, or a launch file in "
        "the workspace) and read by RoboDojo; a node does not import launch"
    ),
    "launch_ros": (
        "a launch file is given to the run (robodojo run --launch FILE, or a launch file in "
        "the workspace) and read by RoboDojo; a node does not import launch_ros"
    ),
    "ament_index_python": (
        "there are no installed ROS packages; open your data files by a path relative to the "
        "workspace (a node's working directory)"
    ),
    "rclcpp": "rclcpp is the C++ client library; Python nodes use rclpy",
    "ros2cli": _CLI_TOOL,
    "ros2topic": f"{_CLI_TOOL}; node.get_topic_names_and_types() lists the topics",
    "ros2node": f"{_CLI_TOOL}; node.get_node_names() lists the nodes",
    "ros2param": f"{_CLI_TOOL}; use node.declare_parameter and node.get_parameter",
    "ros2service": f"{_CLI_TOOL}; call services with node.create_client",
    "rosidl_runtime_py": (
        "read the fields directly; a message's get_fields_and_field_types() lists them"
    ),
    "rclpy_message_converter": (
        "read the fields directly; a message's get_fields_and_field_types() lists them"
    ),
    "cv_bridge": (
        "sensor_msgs/Image data is a bytes field; decode it with numpy: "
        "np.frombuffer(msg.data, np.uint8).reshape(msg.height, msg.width, -1)"
    ),
    "message_filters": (
        "subscribe to each topic with node.create_subscription and pair the latest messages "
        "yourself by header.stamp"
    ),
    "turtlesim": (
        "there is no turtlesim; RoboDojo's robots take geometry_msgs/msg/Twist on cmd_vel like "
        "the turtle and report their pose as nav_msgs/msg/Odometry on odom"
    ),
    "gazebo_msgs": "there is no Gazebo; the robot's pose is in nav_msgs/msg/Odometry on odom",
    "ros_gz_interfaces": "there is no Gazebo; the robot's pose is in nav_msgs/msg/Odometry on odom",
    "tf2_sensor_msgs": (
        "read the cloud with sensor_msgs_py.point_cloud2.read_points_numpy and move the points "
        "with the transform tf2_ros's Buffer.lookup_transform gives (its rotation as a matrix: "
        "tf_transformations.quaternion_matrix)"
    ),
    "tf2_kdl": "use numpy for kinematics and tf_transformations for rotations",
    "tf2_tools": (
        f"{_CLI_TOOL}; a tf2_ros Buffer's all_frames_as_yaml() lists the frames it knows"
    ),
    "transforms3d": (
        "it is not installed; tf_transformations has the functions courses use it for "
        "(euler_from_quaternion, quaternion_from_euler, quaternion_matrix, euler_matrix)"
    ),
    "nav2_common": (
        "its launch helpers are for Nav2's launch files; a run's built-in navigation needs no "
        "parameter files"
    ),
    "robot_localization": (
        "there is no EKF package; the run's localization node publishes the robot's pose"
    ),
    "slam_toolbox": (
        "there is no SLAM; the map comes from the run's map_server on the map topic "
        "(nav_msgs/msg/OccupancyGrid)"
    ),
    "rosbag2_py": (
        "nodes cannot read or write bag files; every run is recorded, and its recording "
        "downloads as MCAP from the run's page (ros2 bag play reads it)"
    ),
    "interactive_markers": "draw with visualization_msgs/msg/Marker and MarkerArray instead",
    "python_qt_binding": (
        "a node has no display; plot with matplotlib and save the figure (plt.savefig), which "
        "comes back with the run's files"
    ),
    "py_trees": "write the behaviour as a state machine stepped by a timer callback",
    "py_trees_ros": "write the behaviour as a state machine stepped by a timer callback",
    "smach": "write the state machine as a loop over a state variable",
    "laser_geometry": (
        "project a sensor_msgs/msg/LaserScan yourself: beam i points at angle msg.angle_min + "
        "i * msg.angle_increment, so x = r * cos(angle), y = r * sin(angle)"
    ),
    "moveit": "there are no arms to plan for; the robots are mobile bases",
    "angles": (
        "normalize an angle with math.atan2(math.sin(a), math.cos(a)); math.radians and "
        "math.degrees convert units"
    ),
    "PyKDL": "use numpy for kinematics and tf_transformations for rotations",
}

# rclpy modules RoboDojo's rclpy leaves out, with what to use instead.
MISSING_RCLPY: dict[str, str] = {
    "rclpy.lifecycle": "lifecycle (managed) nodes are not provided; use a plain rclpy.node.Node",
    "rclpy.parameter_client": (
        "each node's parameters are its own here; read them with node.get_parameter"
    ),
    "rclpy.parameter_event_handler": (
        "each node's parameters are its own here; use node.add_on_set_parameters_callback"
    ),
    "rclpy.type_description_service": "type descriptions are not served in RoboDojo",
    "rclpy.service_introspection": "service introspection is not available in RoboDojo",
    "rclpy.impl": "rclpy's C bindings are not part of RoboDojo's rclpy",
}

# Library packages RoboDojo provides for ROS 2 nodes -> the modules they have (a missing
# submodule, such as nav2_simple_commander.costmap_2d, names them).
LIBRARY_MODULES: dict[str, str] = {
    "nav2_simple_commander": "nav2_simple_commander.robot_navigator (BasicNavigator, TaskResult)",
    "sensor_msgs_py": "sensor_msgs_py.point_cloud2",
    "tf2_ros": (
        "tf2_ros.buffer, tf2_ros.transform_listener, tf2_ros.transform_broadcaster, "
        "tf2_ros.static_transform_broadcaster and tf2_ros.buffer_interface"
    ),
}

_GENERIC_PACKAGE = (
    "RoboDojo provides the interface packages {packages}; for data of your own, std_msgs "
    "(String, Float64, Float64MultiArray...) usually fits"
)


@functools.cache
def interface_packages() -> dict[str, tuple[str, ...]]:
    """Package -> its kinds ("msg", "srv", "action") as they exist in sandbox/ros_compat2."""
    found: dict[str, tuple[str, ...]] = {}
    if not os.path.isdir(ROS_COMPAT2_DIR):
        return found
    for package in sorted(os.listdir(ROS_COMPAT2_DIR)):
        directory = os.path.join(ROS_COMPAT2_DIR, package)
        kinds = tuple(
            kind
            for kind in _INTERFACE_KINDS
            if os.path.exists(os.path.join(directory, kind + ".py"))
            or os.path.exists(os.path.join(directory, kind, "__init__.py"))
        )
        if kinds:
            found[package] = kinds
    return found


def sentence_for(fullname: str) -> str | None:
    """Why ``fullname`` cannot be imported in a ROS 2 node and what to use, or None."""
    top, _, rest = fullname.partition(".")
    for module, reason in MISSING_RCLPY.items():
        if fullname == module or fullname.startswith(module + "."):
            return f"{fullname} is not available in RoboDojo: {reason}"
    if top in MISSING_MODULES:
        return f"{top} is not available in RoboDojo: {MISSING_MODULES[top]}"
    if top in LIBRARY_MODULES and rest:
        return f"{fullname} is not available in RoboDojo: it has {LIBRARY_MODULES[top]}"
    ours = interface_packages()
    if top in ours and rest:
        kind, _, name = rest.partition(".")
        if kind in ours[top] and name:
            return f"{fullname} is not a module: write `from {top}.{kind} import {name}`"
        modules = " and ".join(f"{top}.{kind}" for kind in ours[top])
        return f"{fullname} is not available in RoboDojo: {top} has {modules} only"
    provided = os.path.isdir(os.path.join(ROS_COMPAT2_DIR, top))  # tf2_geometry_msgs is code
    if top.endswith(("_msgs", "_srvs", "_interfaces")) and top not in ours and not provided:
        packages = ", ".join(ours)
        return f"{top} is not available in RoboDojo: {_GENERIC_PACKAGE.format(packages=packages)}"
    return None


class MissingRos2ModuleFinder:
    """Meta-path finder that turns "No module named" into a sentence in a ROS 2 node."""

    @classmethod
    def find_spec(
        cls,
        fullname: str,
        path: Sequence[str] | None = None,
        target: ModuleType | None = None,
    ) -> None:
        sentence = sentence_for(fullname)
        if sentence is not None:
            raise ModuleNotFoundError(sentence, name=fullname)
        return None


def install() -> None:
    """Append the finder to ``sys.meta_path`` (idempotent): it runs after every other finder."""
    if MissingRos2ModuleFinder not in sys.meta_path:
        sys.meta_path.append(MissingRos2ModuleFinder)


def uninstall() -> None:
    while MissingRos2ModuleFinder in sys.meta_path:
        sys.meta_path.remove(MissingRos2ModuleFinder)
