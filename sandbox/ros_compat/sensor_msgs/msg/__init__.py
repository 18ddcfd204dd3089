"""`sensor_msgs.msg`: the message classes of sandbox.msgs.sensor_msgs, built on first use."""

from sandbox.msgs._lazy import install

install(globals(), "sensor_msgs", ("msg",))
