"""`geometry_msgs` for student code: `from geometry_msgs.msg import ...` (see sandbox.msgs)."""
