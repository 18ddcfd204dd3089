#!/usr/bin/env python3
# Course pattern: a plotting node (heavy imports at the top) that saves its figure in on_shutdown.
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import rospy
from scipy.signal import medfilt
from std_msgs.msg import Int32

times = []
distances = []


def callback(msg):
    times.append(rospy.get_time())
    distances.append(msg.data)


def save_plot():
    rospy.loginfo("saving %d samples", len(distances))
    plt.figure(figsize=(8, 4))
    plt.plot(times, distances, ".", label="raw")
    plt.plot(times, medfilt(distances, 5), label="median of 5")
    plt.xlabel("time [s]")
    plt.ylabel("distance [cm]")
    plt.legend()
    plt.savefig("distance.png")


rospy.init_node("live_plot")
rospy.Subscriber("Distance", Int32, callback)
rospy.on_shutdown(save_plot)
rospy.spin()
