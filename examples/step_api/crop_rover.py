"""Crop rover, step API: hold the heading it started with, steering through the control word.

Topics: psi (std_msgs/Float32, yaw [rad]) in; u (std_msgs/Float32, -100..100, negative steers
left) and cmd_vel out. The first command drives forward; then u corrects the heading.
Paper: 001_8d7ab1b8a58c0603.txt section 2.1 (psi from the BNO055, the control word u).
"""

import math

from std_msgs.msg import Float32

RATE_HZ = 10  # [Hz]
SUBSCRIBE = ["psi", "scan"]
GAIN_U_PER_RAD = 120.0  # [1/rad] control word per radian of heading error
heading_rad = None


def setup(info):
    print(f"crop rover controller on {info.robot}, topics {[t.name for t in info.robot_topics]}")


def step(obs):
    global heading_rad
    if obs.psi is None:
        return 0.2, 0.0  # (v [m/s], w [rad/s]) until the IMU reports
    if heading_rad is None:
        heading_rad = obs.psi.data
    error = math.atan2(math.sin(obs.psi.data - heading_rad), math.cos(obs.psi.data - heading_rad))
    # Yaw grew (turned left): steer right, which is a positive control word.
    return {"u": Float32(max(-100.0, min(100.0, GAIN_U_PER_RAD * error)))}
