"""Face the light: the P controller of 000_32b6074bbd2115c3.txt eq. 5, w = K_w (L_d - L_l),
K_w = 2 (Table 2), at 10 Hz. Reference solution of `crowbot_light_tracking`.

L_d and L_l are the right and left light readings scaled to 0..1 (raw / 4095). A reading falls
as the light grows, so a light on the left makes L_l smaller than L_d and w positive: the robot
turns left, towards it.
"""

RATE_HZ = 10  # [Hz]
SUBSCRIBE = ["Light"]
K_W = 2.0  # [rad/s] per unit of reading difference, Table 2


def step(obs):
    if obs.Light is None:
        return (0.0, 0.0)
    right_raw, left_raw = obs.Light.data
    turn = K_W * (right_raw / 4095.0 - left_raw / 4095.0)
    return (0.0, turn)
