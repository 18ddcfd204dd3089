"""`std_msgs` for student code: `from std_msgs.msg import ...` (see sandbox.msgs)."""
