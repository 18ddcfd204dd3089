"""actionlib_msgs: goal ids and statuses of ROS 1 actions (ros/common_msgs).

Each class is built on first use from the definitions in ``_definitions.py``.
"""

from ._lazy import install

install(globals(), "actionlib_msgs", ("msg", "srv"))
