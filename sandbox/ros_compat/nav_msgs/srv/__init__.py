"""`nav_msgs.srv`: the service classes of sandbox.msgs.nav_msgs, built on first use."""

from sandbox.msgs._lazy import install

install(globals(), "nav_msgs", ("srv",))
