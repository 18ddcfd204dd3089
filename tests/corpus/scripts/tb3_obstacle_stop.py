#!/usr/bin/env python3
# Course pattern: TurtleBot3 obstacle stop (LDS-01: 360 beams, index 0 straight ahead).
import rospy
from geometry_msgs.msg import Twist
from sensor_msgs.msg import LaserScan

STOP_DISTANCE = 0.35  # m
LINEAR_VEL = 0.15  # m/s


class Obstacle:
    def __init__(self):
        self._cmd_pub = rospy.Publisher("cmd_vel", Twist, queue_size=1)
        self.obstacle()

    def get_scan(self):
        scan = rospy.wait_for_message("scan", LaserScan)
        samples = len(scan.ranges)
        window = 15
        ranges = list(scan.ranges[samples - window :]) + list(scan.ranges[: window + 1])
        ranges = [r if scan.range_min < r < scan.range_max else 3.5 for r in ranges]
        return min(ranges)

    def obstacle(self):
        twist = Twist()
        stopped = False
        while not rospy.is_shutdown():
            front = self.get_scan()
            if front < STOP_DISTANCE:
                twist.linear.x = 0.0
                if not stopped:
                    rospy.loginfo("Stop! obstacle at %.2f m", front)
                    stopped = True
            else:
                twist.linear.x = LINEAR_VEL
            self._cmd_pub.publish(twist)


def main():
    rospy.init_node("turtlebot3_obstacle")
    try:  # noqa: SIM105
        Obstacle()
    except rospy.ROSInterruptException:
        pass


if __name__ == "__main__":
    main()
