"""`std_msgs.msg`: the message classes of sandbox.msgs.std_msgs, built on first use."""

from sandbox.msgs._lazy import install

install(globals(), "std_msgs", ("msg",))
