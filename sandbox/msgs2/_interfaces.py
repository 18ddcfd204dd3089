"""ROS 2 Jazzy interfaces that rosbags' type store does not carry, as ``.msg``/``.srv`` text.

Field lists (facts, without the files' comments) from the Jazzy branches of
ros2/common_interfaces (std_srvs, nav_msgs/srv), ros2/rcl_interfaces (rcl_interfaces/srv,
action_msgs/srv), ros2/example_interfaces, ros2/demos (action_tutorials_interfaces) and
ros-navigation/navigation2 (nav2_msgs). Read by ``_generate.py`` only.

``robodojo_msgs`` is ours: the ROS 2 twins of ``sandbox/services.py``'s wrappers, which carry
a service request or response between nodes as CDR bytes.
"""

from __future__ import annotations

_NUMBERS = ("int8", "uint8", "int16", "uint16", "int32", "uint32", "int64", "uint64")


def _example_interfaces() -> dict[str, str]:
    """example_interfaces/msg: std_msgs' simple types again (its WString is left out)."""
    messages = {
        "Bool": "bool data",
        "Byte": "byte data",
        "Char": "char data",
        "Empty": "",
        "Float32": "float32 data",
        "Float64": "float64 data",
        "String": "string data",
        "MultiArrayDimension": "string label\nuint32 size\nuint32 stride",
        "MultiArrayLayout": "MultiArrayDimension[] dim\nuint32 data_offset",
        "ByteMultiArray": "MultiArrayLayout layout\nbyte[] data",
        "Float32MultiArray": "MultiArrayLayout layout\nfloat32[] data",
        "Float64MultiArray": "MultiArrayLayout layout\nfloat64[] data",
    }
    for number in _NUMBERS:
        name = number.capitalize() if number[0] == "i" else "UInt" + number[4:]
        messages[name] = f"{number} data"
        messages[f"{name}MultiArray"] = f"MultiArrayLayout layout\n{number}[] data"
    return {f"example_interfaces/msg/{name}": text for name, text in messages.items()}


EXTRA_MESSAGES: dict[str, str] = {
    **_example_interfaces(),
    "nav2_msgs/msg/MissedWaypoint": (
        "uint32 index\ngeometry_msgs/PoseStamped goal\nuint16 error_code"
    ),
    "robodojo_msgs/msg/ServiceCall": (
        "string service\nstring reply_to\nuint32 id\nuint8[] request"
    ),
    "robodojo_msgs/msg/ServiceReply": "uint32 id\nbool ok\nstring error\nuint8[] response",
}

_SET_BOOL = ("bool data", "bool success\nstring message")
_TRIGGER = ("", "bool success\nstring message")

SERVICES: dict[str, tuple[str, str]] = {
    "std_srvs/srv/Empty": ("", ""),
    "std_srvs/srv/SetBool": _SET_BOOL,
    "std_srvs/srv/Trigger": _TRIGGER,
    "example_interfaces/srv/AddTwoInts": ("int64 a\nint64 b", "int64 sum"),
    "example_interfaces/srv/SetBool": _SET_BOOL,
    "example_interfaces/srv/Trigger": _TRIGGER,
    "action_msgs/srv/CancelGoal": (
        "GoalInfo goal_info",
        "int8 ERROR_NONE=0\nint8 ERROR_REJECTED=1\nint8 ERROR_UNKNOWN_GOAL_ID=2\n"
        "int8 ERROR_GOAL_TERMINATED=3\nint8 return_code\nGoalInfo[] goals_canceling",
    ),
    "nav_msgs/srv/GetMap": ("", "OccupancyGrid map"),
    "nav_msgs/srv/GetPlan": (
        "geometry_msgs/PoseStamped start\ngeometry_msgs/PoseStamped goal\nfloat32 tolerance",
        "Path plan",
    ),
    "nav_msgs/srv/LoadMap": (
        "string map_url",
        "uint8 RESULT_SUCCESS=0\nuint8 RESULT_MAP_DOES_NOT_EXIST=1\n"
        "uint8 RESULT_INVALID_MAP_DATA=2\nuint8 RESULT_INVALID_MAP_METADATA=3\n"
        "uint8 RESULT_UNDEFINED_FAILURE=255\n"
        "nav_msgs/OccupancyGrid map\nuint8 result",
    ),
    "nav_msgs/srv/SetMap": (
        "nav_msgs/OccupancyGrid map\ngeometry_msgs/PoseWithCovarianceStamped initial_pose",
        "bool success",
    ),
    # Ours: the service of the thesis's Stanley controller plugin (003_4f92d1fa0a49ddae.txt
    # section 5.9): the robot's pose and the path in, the velocities the controller server
    # publishes out (server/runs/nav2_server.py calls it each control period).
    "robodojo_msgs/srv/ComputeVelocityCommands": (
        "geometry_msgs/PoseStamped pose\nnav_msgs/Path path",
        "geometry_msgs/Twist cmd_vel",
    ),
    "rcl_interfaces/srv/DescribeParameters": (
        "string[] names",
        "ParameterDescriptor[] descriptors",
    ),
    "rcl_interfaces/srv/GetLoggerLevels": ("string[] names", "LoggerLevel[] levels"),
    "rcl_interfaces/srv/GetParameterTypes": ("string[] names", "uint8[] types"),
    "rcl_interfaces/srv/GetParameters": ("string[] names", "ParameterValue[] values"),
    "rcl_interfaces/srv/ListParameters": (
        "uint64 DEPTH_RECURSIVE=0\nstring[] prefixes\nuint64 depth",
        "ListParametersResult result",
    ),
    "rcl_interfaces/srv/SetLoggerLevels": (
        "LoggerLevel[] levels",
        "SetLoggerLevelsResult[] results",
    ),
    "rcl_interfaces/srv/SetParameters": ("Parameter[] parameters", "SetParametersResult[] results"),
    "rcl_interfaces/srv/SetParametersAtomically": (
        "Parameter[] parameters",
        "SetParametersResult result",
    ),
}

_FIBONACCI_GOAL = "int32 order"

ACTIONS: dict[str, tuple[str, str, str]] = {
    "example_interfaces/action/Fibonacci": (
        _FIBONACCI_GOAL,
        "int32[] sequence",
        "int32[] sequence",
    ),
    "action_tutorials_interfaces/action/Fibonacci": (
        _FIBONACCI_GOAL,
        "int32[] sequence",
        "int32[] partial_sequence",
    ),
    "nav2_msgs/action/NavigateToPose": (
        "geometry_msgs/PoseStamped pose\nstring behavior_tree",
        "uint16 NONE=0\nuint16 error_code\nstring error_msg",
        "geometry_msgs/PoseStamped current_pose\nbuiltin_interfaces/Duration navigation_time\n"
        "builtin_interfaces/Duration estimated_time_remaining\nint16 number_of_recoveries\n"
        "float32 distance_remaining",
    ),
    "nav2_msgs/action/NavigateThroughPoses": (
        "geometry_msgs/PoseStamped[] poses\nstring behavior_tree",
        "uint16 NONE=0\nuint16 error_code\nstring error_msg",
        "geometry_msgs/PoseStamped current_pose\nbuiltin_interfaces/Duration navigation_time\n"
        "builtin_interfaces/Duration estimated_time_remaining\nint16 number_of_recoveries\n"
        "float32 distance_remaining\nint16 number_of_poses_remaining",
    ),
    "nav2_msgs/action/FollowWaypoints": (
        "uint32 number_of_loops\nuint32 goal_index 0\ngeometry_msgs/PoseStamped[] poses",
        "uint16 NONE=0\nuint16 UNKNOWN=600\nuint16 TASK_EXECUTOR_FAILED=601\n"
        "MissedWaypoint[] missed_waypoints\nuint16 error_code\nstring error_msg",
        "uint32 current_waypoint",
    ),
    "nav2_msgs/action/ComputePathToPose": (
        "geometry_msgs/PoseStamped goal\ngeometry_msgs/PoseStamped start\nstring planner_id\n"
        "bool use_start",
        "uint16 NONE=0\nuint16 UNKNOWN=200\nuint16 INVALID_PLANNER=201\nuint16 TF_ERROR=202\n"
        "uint16 START_OUTSIDE_MAP=203\nuint16 GOAL_OUTSIDE_MAP=204\nuint16 START_OCCUPIED=205\n"
        "uint16 GOAL_OCCUPIED=206\nuint16 TIMEOUT=207\nuint16 NO_VALID_PATH=208\n"
        "nav_msgs/Path path\nbuiltin_interfaces/Duration planning_time\nuint16 error_code\n"
        "string error_msg",
        "",
    ),
}
