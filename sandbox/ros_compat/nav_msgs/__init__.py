"""`nav_msgs` for student code: `from nav_msgs.msg import ...` (see sandbox.msgs)."""
