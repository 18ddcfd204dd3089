"""`std_msgs.msg`: the ROS 2 message classes of sandbox.msgs2, built on first use."""

from sandbox.msgs2._lazy import install

install(globals(), "std_msgs", "msg")
