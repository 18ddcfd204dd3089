"""The mission of `turtlebot_stanley_ros2`: three NavigateToPose goals, one after another, sent
with Nav2's BasicNavigator (nav2_simple_commander), as a ROS 2 course's first Nav2 script does.
It is complete: read it to see the client's side of the action your controller serves.

For each waypoint it sends a goal (goToPose), watches the feedback the navigator sends back
(distance remaining, time navigating) until the task is complete, and reads the result. The
navigator plans a path and calls your `compute_velocity_commands` service every control period.
"""

import math

import rclpy
from geometry_msgs.msg import PoseStamped
from nav2_simple_commander.robot_navigator import BasicNavigator, TaskResult
from rclpy.duration import Duration

# Out of the lab, into the south-east office and back out, past the open-plan room's column.
WAYPOINTS = [(3.0, 3.1, 0.0), (6.0, 1.4, -math.pi / 2), (6.8, 4.6, math.pi / 2)]  # [m, m, rad]
REPORT_EVERY_S = 5.0  # [s] how often the distance left is logged


def goal_pose(navigator, x, y, yaw):
    goal = PoseStamped()
    goal.header.frame_id = "map"
    goal.header.stamp = navigator.get_clock().now().to_msg()
    goal.pose.position.x = x
    goal.pose.position.y = y
    goal.pose.orientation.z = math.sin(yaw / 2)
    goal.pose.orientation.w = math.cos(yaw / 2)
    return goal


def main():
    rclpy.init()
    navigator = BasicNavigator()
    navigator.waitUntilNav2Active()
    for number, (x, y, yaw) in enumerate(WAYPOINTS, start=1):
        navigator.goToPose(goal_pose(navigator, x, y, yaw))
        next_report = navigator.get_clock().now() + Duration(seconds=REPORT_EVERY_S)
        while not navigator.isTaskComplete():
            feedback = navigator.getFeedback()
            if feedback and navigator.get_clock().now() >= next_report:
                next_report += Duration(seconds=REPORT_EVERY_S)
                navigator.get_logger().info(
                    f"waypoint {number}: {feedback.distance_remaining:.2f} m to go"
                )
        result = navigator.getResult()
        if result == TaskResult.SUCCEEDED:
            navigator.get_logger().info(f"waypoint {number} reached")
        else:
            navigator.get_logger().error(f"waypoint {number} not reached: {result}")
            break
    rclpy.shutdown()


if __name__ == "__main__":
    main()
