"""Face the light with a proportional controller (000_32b6074bbd2115c3.txt eq. 5, Table 2):
w = K_w (L_d - L_l), K_w = 2, where L_d and L_l are the right and left light readings.

`Light` is std_msgs/Int32MultiArray with data = [right, left], each 0..4095; a reading FALLS as
the light grows. Return (0.0, w): turn in place, w [rad/s] positive to the left.
"""

RATE_HZ = 10  # [Hz]
SUBSCRIBE = ["Light"]
K_W = 2.0


def step(obs):
    if obs.Light is None:
        return (0.0, 0.0)
    right_raw, left_raw = obs.Light.data
    turn = 0.0 * (right_raw - left_raw)  # TODO: eq. 5 with K_W and readings scaled to 0..1
    return (0.0, turn)
