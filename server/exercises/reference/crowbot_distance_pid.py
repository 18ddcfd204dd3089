"""Hold the CrowBot 0.2 m from the wall: the PID of 000_32b6074bbd2115c3.txt eq. 3-4 with the
gains of Table 2 (Kp = Ki = Kd = 0.4) at 10 Hz, written as the paper's ROS 1 Python programs are:
a subscriber callback keeps the latest distance, a Rate loop publishes the Twist. Reference
solution of the `crowbot_distance_pid` exercise (not shown to students).

    robodojo check crowbot_distance_pid --reference
"""

import rospy
from geometry_msgs.msg import Twist
from std_msgs.msg import Int32

KP, KI, KD = 0.4, 0.4, 0.4  # Table 2
SETPOINT_M = 0.2  # d_d [m]
RATE_HZ = 10  # [Hz] the paper's control rate
MAX_SPEED_M_S = 0.128  # [m/s] what PWM 255 gives the wheels; beyond it the integral winds up
INTEGRATE_WITHIN_M = 0.05  # [m] the integral only acts on the last few centimetres

distance_m = None


def on_distance(msg):
    global distance_m
    if msg.data > 0:  # 0 means no echo: keep the last good reading
        distance_m = msg.data / 100.0


rospy.init_node("pid_distance")
rospy.Subscriber("Distance", Int32, on_distance)
control = rospy.Publisher("Control", Twist, queue_size=10)
rate = rospy.Rate(RATE_HZ)
integral, previous_error = 0.0, None
period = 1.0 / RATE_HZ
while not rospy.is_shutdown():
    if distance_m is not None:
        # eq. 3 writes e = d_d - d_r; the robot drives forward (positive u) when too far, so
        # the command uses the opposite sign.
        error = distance_m - SETPOINT_M
        derivative = 0.0 if previous_error is None else (error - previous_error) / period
        command = KP * error + KI * integral + KD * derivative
        # Anti-windup: integrate only near the set point and while the wheels are not
        # saturated; integrating the whole approach would carry the robot past 0.2 m.
        if abs(command) < MAX_SPEED_M_S and abs(error) < INTEGRATE_WITHIN_M:
            integral += error * period
        previous_error = error
        move = Twist()
        move.linear.x = max(-MAX_SPEED_M_S, min(MAX_SPEED_M_S, command))
        control.publish(move)
        rospy.loginfo("distance %.3f m, error %+.3f m, u %+.3f m/s", distance_m, error, command)
    rate.sleep()
