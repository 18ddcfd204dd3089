"""`nav2_msgs.action`: the ROS 2 action classes of sandbox.msgs2, built on first use."""

from sandbox.msgs2._lazy import install

install(globals(), "nav2_msgs", "action")
