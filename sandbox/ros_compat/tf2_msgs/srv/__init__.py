"""`tf2_msgs.srv`: the service classes of sandbox.msgs.tf2_msgs, built on first use."""

from sandbox.msgs._lazy import install

install(globals(), "tf2_msgs", ("srv",))
