"""`sensor_msgs.srv`: the service classes of sandbox.msgs.sensor_msgs, built on first use."""

from sandbox.msgs._lazy import install

install(globals(), "sensor_msgs", ("srv",))
