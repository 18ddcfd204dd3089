#!/usr/bin/env python3
# Course pattern: a class-based node (publishers and subscribers in __init__, a run() loop).
import rospy
from geometry_msgs.msg import Twist
from std_msgs.msg import Int32


class WallApproacher:
    def __init__(self):
        rospy.init_node("wall_approacher")
        self.goal_cm = 30
        self.gain = 0.01
        self.distance_cm = None
        self.cmd_pub = rospy.Publisher("Control", Twist, queue_size=1)
        self.sub = rospy.Subscriber("Distance", Int32, self.distance_callback)
        self.rate = rospy.Rate(10)

    def distance_callback(self, msg):
        if msg.data > 0:
            self.distance_cm = msg.data

    def compute_command(self):
        cmd = Twist()
        if self.distance_cm is not None:
            error = self.distance_cm - self.goal_cm
            cmd.linear.x = max(-0.1, min(0.1, self.gain * error))
        return cmd

    def run(self):
        while not rospy.is_shutdown():
            self.cmd_pub.publish(self.compute_command())
            self.rate.sleep()


if __name__ == "__main__":
    node = WallApproacher()
    try:  # noqa: SIM105
        node.run()
    except rospy.ROSInterruptException:
        pass
