"""CrowBot, step API: drive forward, stop 20 cm before an obstacle, LEDs red while stopped.

Topics: Distance (std_msgs/Int32, cm; 0 = no echo) in, Control (Twist) and Leds out.
Paper: 000_32b6074bbd2115c3.txt section 2.3 and Table 1 (the firmware's topics).
"""

from std_msgs.msg import Int32MultiArray

RATE_HZ = 20  # [Hz] the firmware publishes Distance at 20 Hz
SUBSCRIBE = ["Distance"]
STOP_CM = 20  # [cm]
SPEED_M_S = 0.1  # [m/s]


def step(obs):
    if obs.Distance is None:
        return None  # no reading yet
    blocked = 0 < obs.Distance.data < STOP_CM
    return {
        "Control": (0.0, 0.0) if blocked else (SPEED_M_S, 0.0),
        "Leds": Int32MultiArray(data=[255, 0, 0] if blocked else [0, 64, 0]),
    }
