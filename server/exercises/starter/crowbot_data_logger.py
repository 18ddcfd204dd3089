"""Record the CrowBot's button, distance, light and line readings at 10 Hz for the whole run,
then save them to a CSV file (samples.csv: time_s, button, distance_cm, light_right,
light_left, line_right, line_left) and a figure of them (readings.png), as the data-acquisition
programs of 000_32b6074bbd2115c3.txt section 3.2 do.
"""

import rospy
from std_msgs.msg import Int32

RATE_HZ = 10  # [Hz]
latest = {"Distance": 0}


def on_distance(msg):
    latest["Distance"] = msg.data


rospy.init_node("data_logger")
rospy.Subscriber("Distance", Int32, on_distance)
rate = rospy.Rate(RATE_HZ)
try:
    while not rospy.is_shutdown():
        # TODO: subscribe to Button, Light and Line too, keep a row per period, and after the
        # loop write samples.csv and plot readings.png with matplotlib.
        rate.sleep()
except rospy.ROSInterruptException:
    pass
