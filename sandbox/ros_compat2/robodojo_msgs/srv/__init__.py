"""`robodojo_msgs.srv`: the ROS 2 service classes of sandbox.msgs2, built on first use."""

from sandbox.msgs2._lazy import install

install(globals(), "robodojo_msgs", "srv")
