"""Servo node (002_3fcfeb7b4c14107a.txt section II-E, Fig. 3 and 6; node `servo` in Fig. 8).

While the robot drives, point the IR ranger 90 -> 45 -> 90 -> 135 degrees over and over
(`servo_angle`, std_msgs/Int16: 0 right .. 90 ahead .. 180 left) and read `distance_detect`
(std_msgs/Float32, cm) at each angle. When a reading is under 15 cm:
1. publish `dist_detect` (std_msgs/Int16) so the dc_motor node stops the robot;
2. look right (0 degrees) and left (180 degrees);
3. publish the two distances on `dist_detect_right` and `dist_detect_left` (std_msgs/Int16, cm);
4. look ahead and wait for a message on `forward` (std_msgs/String) before sweeping again.

The servo turns at about 500 deg/s and reports nothing back: after pointing it, wait until it
has arrived (a 90 degree swing takes ~0.2 s) before you trust a reading.
"""

import rospy
from std_msgs.msg import Float32, Int16, String

SWEEP_DEG = (90, 45, 90, 135)
STOP_BELOW_CM = 15.0  # [cm]

rospy.init_node("servo")
servo_angle = rospy.Publisher("servo_angle", Int16, queue_size=1)
dist_detect = rospy.Publisher("dist_detect", Int16, queue_size=1)
dist_right = rospy.Publisher("dist_detect_right", Int16, queue_size=1)
dist_left = rospy.Publisher("dist_detect_left", Int16, queue_size=1)


def on_distance(msg):
    # TODO: sweep SWEEP_DEG; under STOP_BELOW_CM stop, look right and left, publish both.
    pass


def on_forward(msg):
    # TODO: the robot drives again: resume the sweep.
    pass


rospy.Subscriber("distance_detect", Float32, on_distance)
rospy.Subscriber("forward", String, on_forward)
servo_angle.publish(Int16(90))  # look ahead
rospy.spin()
