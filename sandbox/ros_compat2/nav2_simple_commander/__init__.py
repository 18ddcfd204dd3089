"""`nav2_simple_commander` for ROS 2 student code: BasicNavigator and TaskResult (in
robot_navigator), driving the run's built-in navigation server through Nav2's actions."""
