"""nav_msgs: odometry, occupancy grid maps and paths (definitions as in ros/common_msgs)."""

from __future__ import annotations

from . import geometry_msgs as _geometry_msgs  # noqa: F401  # registers nested types
from ._core import Message


class MapMetaData(Message):
    """Grid resolution [m/cell], size [cells] and the pose of cell (0, 0) in the map frame."""

    _type = "nav_msgs/MapMetaData"
    _definition = """
# This hold basic information about the characterists of the OccupancyGrid

# The time at which the map was loaded
time map_load_time
# The map resolution [m/cell]
float32 resolution
# Map width [cells]
uint32 width
# Map height [cells]
uint32 height
# The origin of the map [m, m, rad].  This is the real-world pose of the
# cell (0,0) in the map.
geometry_msgs/Pose origin
"""


class OccupancyGrid(Message):
    """Row-major occupancy probabilities 0..100, -1 for unknown."""

    _type = "nav_msgs/OccupancyGrid"
    _definition = """
# This represents a 2-D grid map, in which each cell represents the probability of
# occupancy.

Header header

#MetaData for the map
MapMetaData info

# The map data, in row-major order, starting with (0,0).  Occupancy
# probabilities are in the range [0,100].  Unknown is -1.
int8[] data
"""


class Odometry(Message):
    """Pose in ``header.frame_id`` and velocity in ``child_frame_id``."""

    _type = "nav_msgs/Odometry"
    _definition = """
# This represents an estimate of a position and velocity in free space.
# The pose in this message should be specified in the coordinate frame given by header.frame_id.
# The twist in this message should be specified in the coordinate frame given by the child_frame_id
Header header
string child_frame_id
geometry_msgs/PoseWithCovariance pose
geometry_msgs/TwistWithCovariance twist
"""


class Path(Message):
    _type = "nav_msgs/Path"
    _definition = """
#An array of poses that represents a Path for a robot to follow
Header header
geometry_msgs/PoseStamped[] poses
"""
