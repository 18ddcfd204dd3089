#!/usr/bin/env python3
# Course pattern: the CrowBot paper's P light tracker (w = K_w (L_d - L_l), K_w = 2, 10 Hz),
# topics set up before init_node, then signal_shutdown and two 2400x1200 figures.
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import rospy
from geometry_msgs.msg import Twist
from std_msgs.msg import Int32MultiArray

Kw = 2.0
duration = 5.0

Ld = 0.0  # right light sensor, 0..1
Ll = 0.0  # left light sensor, 0..1


def light_cb(msg):
    global Ld, Ll
    Ld = (4095.0 - msg.data[0]) / 4095.0
    Ll = (4095.0 - msg.data[1]) / 4095.0


pub = rospy.Publisher("Control", Twist, queue_size=10)
rospy.Subscriber("Light", Int32MultiArray, light_cb)
rospy.init_node("light_tracking")
rate = rospy.Rate(10)

t_list, e_list, w_list = [], [], []
t0 = rospy.get_time()
while not rospy.is_shutdown() and rospy.get_time() - t0 < duration:
    error = Ll - Ld
    wc = -Kw * (Ld - Ll)
    vel = Twist()
    vel.angular.z = wc
    pub.publish(vel)
    t_list.append(rospy.get_time() - t0)
    e_list.append(error)
    w_list.append(wc)
    rate.sleep()

pub.publish(Twist())
rospy.signal_shutdown("light tracking finished")

fig1 = plt.figure(figsize=(12, 6), dpi=200)
plt.plot(t_list, e_list)
plt.xlabel("t [s]")
plt.ylabel("L_l - L_d")
plt.savefig("light_error.png")

fig2 = plt.figure(figsize=(12, 6), dpi=200)
plt.plot(t_list, w_list)
plt.xlabel("t [s]")
plt.ylabel("w [rad/s]")
plt.savefig("light_control.png")
