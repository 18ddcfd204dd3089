"""TurtleBot3 Burger, step API: follow the wall on the right at 0.3 m, stopping short of walls.

Topic: scan (sensor_msgs/LaserScan from the LDS-01: 360 ranges, index 0 straight ahead,
counter-clockwise, so index 270 is the right side; 0.0 means no return) in; cmd_vel (Twist)
out via a (v, w) pair. The firmware stops the wheels 0.5 s after the last command, so this
answers every scan.
"""

RATE_HZ = 10  # [Hz]
SUBSCRIBE = ["scan"]
WALL_M = 0.3  # [m] distance to keep from the wall on the right
STOP_M = 0.25  # [m] anything this close ahead: turn left on the spot
SPEED_M_S = 0.15  # [m/s]
GAIN_RAD_S_PER_M = 2.0  # [rad/s per m] steering per metre of wall-distance error


def nearest(ranges, first, last):
    """The nearest valid reading between beam indices first..last (inclusive, wrapping)."""
    picked = [ranges[i % 360] for i in range(first, last + 1)]
    valid = [r for r in picked if r > 0.0]  # 0.0 is the LDS-01's "no return"
    return min(valid) if valid else float("inf")


def step(obs):
    if obs.scan is None or len(obs.scan.ranges) != 360:
        return 0.0, 0.0
    ranges = obs.scan.ranges
    ahead = nearest(ranges, -20, 20)
    if ahead < STOP_M:
        return 0.0, 1.0
    right = min(nearest(ranges, 250, 290), 1.0)  # no wall in sight: curve right to find one
    return SPEED_M_S, -GAIN_RAD_S_PER_M * (right - WALL_M)  # too far: turn right (w < 0)
