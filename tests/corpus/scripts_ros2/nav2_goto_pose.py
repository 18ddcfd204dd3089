#!/usr/bin/env python3
# Course pattern: Nav2's simple commander (BasicNavigator) - initial pose, waitUntilNav2Active,
# goToPose, poll isTaskComplete/getFeedback, then getResult.
import rclpy
from geometry_msgs.msg import PoseStamped
from nav2_simple_commander.robot_navigator import BasicNavigator, TaskResult
from rclpy.duration import Duration


def main():
    rclpy.init()
    navigator = BasicNavigator()

    initial_pose = PoseStamped()
    initial_pose.header.frame_id = "map"
    initial_pose.header.stamp = navigator.get_clock().now().to_msg()
    initial_pose.pose.position.x = 2.0
    initial_pose.pose.position.y = 1.3
    initial_pose.pose.orientation.z = 0.7071068
    initial_pose.pose.orientation.w = 0.7071068
    navigator.setInitialPose(initial_pose)
    navigator.waitUntilNav2Active()

    goal_pose = PoseStamped()
    goal_pose.header.frame_id = "map"
    goal_pose.header.stamp = navigator.get_clock().now().to_msg()
    goal_pose.pose.position.x = 2.5
    goal_pose.pose.position.y = 2.0
    goal_pose.pose.orientation.w = 1.0
    navigator.goToPose(goal_pose)

    i = 0
    while not navigator.isTaskComplete():
        i += 1
        feedback = navigator.getFeedback()
        if feedback and i % 10 == 0:
            print(f"Distance remaining: {feedback.distance_remaining:.2f} m")
            if Duration.from_msg(feedback.navigation_time) > Duration(seconds=30.0):
                navigator.cancelTask()

    result = navigator.getResult()
    if result == TaskResult.SUCCEEDED:
        print("Goal succeeded!")
    elif result == TaskResult.CANCELED:
        print("Goal was canceled!")
    elif result == TaskResult.FAILED:
        print("Goal failed!")
    navigator.lifecycleShutdown()
    exit(0)


if __name__ == "__main__":
    main()
