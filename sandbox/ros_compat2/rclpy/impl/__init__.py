"""rclpy.impl: here only the logger classes (rcutils_logger, logging_severity)."""
