"""`nav_msgs.msg`: the message classes of sandbox.msgs.nav_msgs, built on first use."""

from sandbox.msgs._lazy import install

install(globals(), "nav_msgs", ("msg",))
