"""TurtleBot, step API: wander, turning away from the nearer side when the scan sees a wall.

Topics: scan (sensor_msgs/LaserScan from the depth camera, 0.3-3 m) and bumper
(std_msgs/Int32MultiArray [left, right]) in; cmd_vel (Twist) out via a (v, w) pair.
Paper: 003_4f92d1fa0a49ddae.txt sections 3.3-3.4 and 5 (depth scan, Roomba base).
"""

import numpy as np

RATE_HZ = 10  # [Hz]
SUBSCRIBE = ["scan", "bumper"]
CLEAR_M = 0.6  # [m] closer than this, turn
SPEED_M_S = 0.15  # [m/s]
TURN_RAD_S = 0.8  # [rad/s]


def step(obs):
    if obs.bumper is not None and any(obs.bumper.data):
        return -0.05, TURN_RAD_S  # back off while turning
    if obs.scan is None or len(obs.scan.ranges) == 0:
        return 0.0, 0.0
    ranges = np.asarray(obs.scan.ranges, dtype=float)
    ranges[~np.isfinite(ranges)] = obs.scan.range_max
    half = len(ranges) // 2
    right, left = ranges[:half].min(), ranges[half:].min()
    if min(left, right) < CLEAR_M:
        return 0.0, -TURN_RAD_S if left < right else TURN_RAD_S
    return SPEED_M_S, 0.0
