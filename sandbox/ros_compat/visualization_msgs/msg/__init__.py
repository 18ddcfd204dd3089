"""`visualization_msgs.msg`: the classes of sandbox.msgs.visualization_msgs, built on first use."""

from sandbox.msgs._lazy import install

install(globals(), "visualization_msgs", ("msg",))
