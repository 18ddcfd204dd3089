"""Sentences for ROS 1 modules RoboDojo does not provide, instead of "No module named ...".

Course scripts import more of ROS 1 than rospy and the message packages: cv_bridge, actionlib,
tf_conversions, rostopic... A finder appended to the end of ``sys.meta_path`` answers only after
every other finder has failed to find a module, and only for the names below (plus any
``*_msgs``/``*_srvs`` package, and a submodule missing from a message package we do have): it
raises ModuleNotFoundError whose message says the module is not available here and what to use
instead. For every other name it returns None, so numpy, the student's own modules and the
packages we provide are untouched and pay nothing.

Alternatives named in the sentences are what RoboDojo offers: rospy, tf.transformations,
tf2_ros, the message packages of ``sandbox.msgs``, parameters from ``--param`` or a launch file.
"""

from __future__ import annotations

import sys
from collections.abc import Sequence
from types import ModuleType

from sandbox.msgs import _catalog

_CLI_TOOL = "a command-line tool, not a library a node can use"
_NO_URDF = "there are no URDF models to parse; the robot's sizes are in the exercise's description"

_ROS2 = (
    "is part of ROS 2 and this run is ROS 1 (its nodes use rospy, and a run is one or the other)"
)

# Top-level module -> what to use instead (the sentence ends the error message).
MISSING_MODULES: dict[str, str] = {
    "rclpy": (
        f"{_ROS2}; write this node with rospy, or every node of the run with rclpy (a file "
        "that imports rclpy runs as ROS 2 when all the run's nodes do)"
    ),
    "tf_transformations": f"{_ROS2}; use tf.transformations, which has the same functions",
    "sensor_msgs_py": (
        f"{_ROS2}; read sensor_msgs/PointCloud2 with numpy: np.frombuffer(msg.data, dtype)"
    ),
    "nav2_simple_commander": f"{_ROS2}; there is no navigation stack in a ROS 1 run",
    "launch_ros": (
        "a launch file is given to the run (robodojo run --launch FILE), not imported by a node"
    ),
    "actionlib": (
        "there are no action servers; use a service (rospy.Service / rospy.ServiceProxy with "
        "std_srvs/Trigger or SetBool) to start a task and topics for its progress"
    ),
    "move_base_msgs": (
        "there is no move_base navigation stack; drive the robot with geometry_msgs/Twist on "
        "cmd_vel and follow its pose in nav_msgs/Odometry on odom"
    ),
    "rospy_tutorials": (
        "the tutorial services (AddTwoInts) are not provided; use std_srvs (SetBool, Trigger) "
        "for a service, or topics with std_msgs types"
    ),
    "turtlesim": (
        "there is no turtlesim; RoboDojo's robots take geometry_msgs/Twist on cmd_vel like the "
        "turtle and report their pose as nav_msgs/Odometry on odom (turtlesim/Pose x, y, theta "
        "are pose.pose.position.x, .y and the yaw of pose.pose.orientation)"
    ),
    "cv_bridge": (
        "sensor_msgs/Image data is a bytes field; decode it with numpy: "
        "np.frombuffer(msg.data, np.uint8).reshape(msg.height, msg.width, -1)"
    ),
    "image_geometry": (
        "camera models are not provided; use the K (3x3) and P (3x4) row-major matrices of "
        "sensor_msgs/CameraInfo with numpy"
    ),
    "message_filters": (
        "subscribe to each topic with rospy.Subscriber and pair the latest messages yourself "
        "by header.stamp"
    ),
    "gazebo_msgs": (
        "there is no Gazebo; the robot's pose is in nav_msgs/Odometry on odom, and a new run "
        "starts from the world's start pose"
    ),
    "gazebo_ros": "there is no Gazebo; the simulator is RoboDojo's own, started with the run",
    "kobuki_msgs": (
        "the Kobuki base's messages are not provided; `robodojo robots` lists each robot's "
        "topics and their std_msgs/sensor_msgs types"
    ),
    "turtlebot3_msgs": (
        "the TurtleBot3's SensorState and Sound messages are not provided; its scan, odom, imu "
        "and cmd_vel topics use sensor_msgs, nav_msgs and geometry_msgs"
    ),
    "dynamic_reconfigure": (
        "parameters are fixed when the run starts: read them with rospy.get_param and set them "
        "with --param NAME=VALUE or a launch file's <param>"
    ),
    "tf_conversions": (
        "use tf.transformations (euler_from_quaternion, quaternion_from_euler, quaternion_matrix)"
    ),
    "laser_geometry": (
        "project a sensor_msgs/LaserScan yourself: beam i points at angle msg.angle_min + i * "
        "msg.angle_increment, so x = r * cos(angle), y = r * sin(angle)"
    ),
    "rosbag": (
        "nodes cannot read or write bag files; every run is recorded, and its recording "
        "downloads as MCAP from the run's page"
    ),
    "roslaunch": (
        "a launch file is given to the run (robodojo run --launch FILE, or a .launch file in "
        "the workspace), not started from a node"
    ),
    "rostopic": f"{_CLI_TOOL}; rospy.get_published_topics() lists the topics",
    "rosnode": f"{_CLI_TOOL}; rospy.get_name() gives this node's name",
    "rosservice": f"{_CLI_TOOL}; call services with rospy.wait_for_service and rospy.ServiceProxy",
    "rosparam": (
        f"{_CLI_TOOL}; use rospy.get_param/rospy.set_param, and a launch file's <rosparam> to "
        "load YAML"
    ),
    "rosmsg": (
        f"{_CLI_TOOL}; a message class has _type, _md5sum and _full_text, and "
        "roslib.message.get_message_class('pkg/Name') finds a class by name"
    ),
    "rosgraph": (
        "the ROS master is not available to nodes; rospy.get_published_topics() lists topics"
    ),
    "rospkg": (
        "there are no ROS packages on disk; open your data files by a path relative to the "
        "workspace (a node's working directory)"
    ),
    "genpy": (
        "message classes come from <package>.msg, and rospy.Time/rospy.Duration are the time types"
    ),
    "smach": "write the state machine as a loop over a state variable",
    "smach_ros": "write the state machine as a loop over a state variable",
    "interactive_markers": "draw with visualization_msgs/Marker and MarkerArray instead",
    "angles": (
        "normalize an angle with math.atan2(math.sin(a), math.cos(a)); math.radians and "
        "math.degrees convert units"
    ),
    "PyKDL": "use numpy for kinematics and tf.transformations for rotations",
    "tf2_kdl": "use numpy for kinematics and tf.transformations for rotations",
    "kdl_parser_py": _NO_URDF,
    "urdf_parser_py": _NO_URDF,
    "tf2_sensor_msgs": (
        "transform points yourself: tf2_ros.Buffer.lookup_transform gives the transform, "
        "tf.transformations.quaternion_matrix its rotation"
    ),
    "tf2_py": "use tf2_ros (Buffer, TransformListener, lookup_transform)",
    "ros_numpy": "convert with numpy directly, e.g. np.frombuffer(msg.data, np.uint8) for an Image",
    "moveit_commander": "there are no arms to plan for; the robots are mobile bases",
    "rosserial_python": (
        "rosserial is spoken by RoboDojo's hardware bridge to real robots, not by nodes; "
        "publish and subscribe with rospy as usual"
    ),
    "rospy_message_converter": (
        "read the fields directly; a message's __slots__ lists its field names"
    ),
}

# Submodules of message packages we have that course scripts import.
MISSING_SUBMODULES: dict[str, str] = {
    "sensor_msgs.point_cloud2": (
        "read sensor_msgs/PointCloud2 with numpy: np.frombuffer(msg.data, dtype) with a dtype "
        "built from msg.fields, reshaped to (msg.height, msg.width)"
    ),
}

_GENERIC_PACKAGE = (
    "RoboDojo provides the message packages {packages}; for data of your own, std_msgs "
    "(String, Float64, Float64MultiArray...) usually fits"
)


def sentence_for(fullname: str) -> str | None:
    """Why ``fullname`` cannot be imported here and what to use, or None if not ours to say."""
    top, _, rest = fullname.partition(".")
    if fullname in MISSING_SUBMODULES:
        return f"{fullname} is not available in RoboDojo: {MISSING_SUBMODULES[fullname]}"
    if top in MISSING_MODULES:
        return f"{top} is not available in RoboDojo: {MISSING_MODULES[top]}"
    if top == "roslib" and rest:
        return (
            f"{fullname} is not available in RoboDojo: roslib has load_manifest (which does "
            "nothing here) and roslib.message (get_message_class, get_service_class) only"
        )
    ours = _catalog.packages()
    if top in ours and rest:
        kind, _, name = rest.partition(".")
        if kind in _catalog.kinds(top) and name:
            return f"{fullname} is not a module: write `from {top}.{kind} import {name}`"
        modules = " and ".join(f"{top}.{kind}" for kind in _catalog.kinds(top))
        return f"{fullname} is not available in RoboDojo: {top} has {modules} only"
    if top.endswith(("_msgs", "_srvs")) and top not in ours:
        packages = ", ".join(ours)
        return f"{top} is not available in RoboDojo: {_GENERIC_PACKAGE.format(packages=packages)}"
    return None


class MissingRosModuleFinder:
    """Meta-path finder that turns "No module named" into a sentence for ROS 1 names."""

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
    if MissingRosModuleFinder not in sys.meta_path:
        sys.meta_path.append(MissingRosModuleFinder)


def uninstall() -> None:
    while MissingRosModuleFinder in sys.meta_path:
        sys.meta_path.remove(MissingRosModuleFinder)
