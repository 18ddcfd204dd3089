"""`sensor_msgs` for student code: `from sensor_msgs.msg import ...` (see sandbox.msgs)."""
