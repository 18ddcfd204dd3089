"""dc_motor node (002_3fcfeb7b4c14107a.txt section II-E, Fig. 4 and 14; node `dc_motor` in
Fig. 8).

Drive the robot with `motor_command` (std_msgs/String: "forward", "backward", "left", "right",
"stop"; the robot keeps doing the last one). Stop when the servo node publishes `dist_detect`;
when `direction` (std_msgs/String) arrives, turn or back up for a while, then drive forward again
and publish on `forward` (std_msgs/String, e.g. "move") so the servo node sweeps again. The robot
turns in place at about 1.5 rad/s and backs up at 0.08 m/s.
"""

import rospy
from std_msgs.msg import Int16, String

LOOP_HZ = 20  # [Hz]

rospy.init_node("dc_motor")
motor = rospy.Publisher("motor_command", String, queue_size=1)
forward = rospy.Publisher("forward", String, queue_size=1)


def on_dist_detect(msg):
    # TODO: an obstacle is near: stop.
    pass


def on_direction(msg):
    # TODO: turn (or back up) for a while, then forward again, and tell the servo node.
    pass


rospy.Subscriber("dist_detect", Int16, on_dist_detect)
rospy.Subscriber("direction", String, on_direction)
rate = rospy.Rate(LOOP_HZ)
rospy.sleep(0.1)  # let the other nodes come up
motor.publish(String("stop"))  # TODO: start by driving forward
while not rospy.is_shutdown():
    rate.sleep()
