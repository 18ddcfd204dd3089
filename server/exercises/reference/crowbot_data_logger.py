"""Data acquisition as the paper's Python programs do it (000_32b6074bbd2115c3.txt section 3.2,
Fig. 10-13): sample the button, distance, light and line readings at 10 Hz for the run, then
save them as a CSV and plot them in one figure. Reference solution of `crowbot_data_logger`.
"""

import matplotlib.pyplot as plt
import rospy
from std_msgs.msg import Bool, Int32, Int32MultiArray

RATE_HZ = 10  # [Hz] the requested sampling rate
latest = {"Button": 0, "Distance": 0, "Light": [0, 0], "Line": [0, 0]}


def keep(topic):
    def callback(msg):
        latest[topic] = msg.data

    return callback


rospy.init_node("data_logger")
rospy.Subscriber("Button", Bool, keep("Button"))
rospy.Subscriber("Distance", Int32, keep("Distance"))
rospy.Subscriber("Light", Int32MultiArray, keep("Light"))
rospy.Subscriber("Line", Int32MultiArray, keep("Line"))
samples = []
rate = rospy.Rate(RATE_HZ)
try:
    while not rospy.is_shutdown():
        light, line = list(latest["Light"]), list(latest["Line"])
        samples.append((rospy.get_time(), int(latest["Button"]), latest["Distance"], *light, *line))
        rate.sleep()
except rospy.ROSInterruptException:
    pass  # the run ended: save what was collected

with open("samples.csv", "w") as f:
    f.write("time_s,button,distance_cm,light_right,light_left,line_right,line_left\n")
    for row in samples:
        f.write(",".join(str(v) for v in row) + "\n")
times = [row[0] for row in samples]
figure, axes = plt.subplots(4, 1, sharex=True, figsize=(8, 8))
axes[0].step(times, [row[1] for row in samples])
axes[0].set_ylabel("button")
axes[1].plot(times, [row[2] for row in samples])
axes[1].set_ylabel("distance [cm]")
axes[2].plot(times, [row[3] for row in samples], label="L1 right")
axes[2].plot(times, [row[4] for row in samples], label="L2 left")
axes[2].set_ylabel("light")
axes[2].legend()
axes[3].plot(times, [row[5] for row in samples], label="S1 right")
axes[3].plot(times, [row[6] for row in samples], label="S2 left")
axes[3].set_ylabel("line")
axes[3].set_xlabel("time [s]")
axes[3].legend()
figure.savefig("readings.png")
