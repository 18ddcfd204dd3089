"""`actionlib_msgs.msg`: the message classes of sandbox.msgs.actionlib_msgs, built on first use."""

from sandbox.msgs._lazy import install

install(globals(), "actionlib_msgs", ("msg",))
