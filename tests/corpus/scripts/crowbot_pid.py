#!/usr/bin/env python3
# Course pattern: the CrowBot paper's PID distance controller (10 Hz, Kp=Ki=Kd=0.4, d_d=0.2 m),
# topics set up before init_node, then signal_shutdown and two 2400x1200 figures.
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import rospy
from geometry_msgs.msg import Twist
from std_msgs.msg import Int32

# Parameters (Table 2)
Kp = 0.4
Ki = 0.4
Kd = 0.4
dd = 0.2  # desired distance [m]
T = 0.1  # sampling period [s]
duration = 8.0  # experiment length [s]

dr = None  # measured distance [m]


def distance_cb(msg):
    global dr
    if msg.data > 0:
        dr = msg.data / 100.0


pub = rospy.Publisher("Control", Twist, queue_size=10)
sub = rospy.Subscriber("Distance", Int32, distance_cb)
rospy.init_node("pid_distance", anonymous=True)
rate = rospy.Rate(1 / T)

times, errors, actions = [], [], []
integral = 0.0
e_prev = 0.0
t0 = rospy.get_time()
while not rospy.is_shutdown():
    t = rospy.get_time() - t0
    if t > duration:
        break
    if dr is None:
        rate.sleep()
        continue
    e = dd - dr
    integral += e * T
    integral = max(-0.05, min(0.05, integral))  # anti windup
    derivative = (e - e_prev) / T
    e_prev = e
    uc = -(Kp * e + Ki * integral + Kd * derivative)
    uc = max(-0.12, min(0.12, uc))
    vel = Twist()
    vel.linear.x = uc
    pub.publish(vel)
    times.append(t)
    errors.append(e)
    actions.append(uc)
    rate.sleep()

pub.publish(Twist())
rospy.signal_shutdown("experiment finished")

plt.figure(figsize=(12, 6), dpi=200)
plt.plot(times, errors, "r")
plt.xlabel("Time [s]")
plt.ylabel("Error [m]")
plt.title("Proximity error")
plt.grid()
plt.savefig("pid_error.png")

plt.figure(figsize=(12, 6), dpi=200)
plt.plot(times, actions, "b")
plt.xlabel("Time [s]")
plt.ylabel("u [m/s]")
plt.title("Control action")
plt.grid()
plt.savefig("pid_control.png")
