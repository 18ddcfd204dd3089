"""`geometry_msgs.msg`: the message classes of sandbox.msgs.geometry_msgs, built on first use."""

from sandbox.msgs._lazy import install

install(globals(), "geometry_msgs", ("msg",))
