"""`example_interfaces.action`: the ROS 2 action classes of sandbox.msgs2, built on first use."""

from sandbox.msgs2._lazy import install

install(globals(), "example_interfaces", "action")
