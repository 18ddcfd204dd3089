"""IR scout, step API: drive forward; turn left while the IR ranger sees something near.

Topics: ir_range (sensor_msgs/Range, metres; inf when nothing is in range) in; motor_command
(std_msgs/String: forward, backward, left, right, stop) out.
Paper: 002_3fcfeb7b4c14107a.txt section II (IR ranger, motor directions of Fig. 14).
"""

RATE_HZ = 10  # [Hz]
SUBSCRIBE = ["ir_range"]
NEAR_M = 0.30  # [m]


def step(obs):
    reading = obs["ir_range"]
    if reading is None:
        return {"motor_command": "stop"}  # a plain value builds the topic's message
    command = "left" if reading.range < NEAR_M else "forward"
    return {"motor_command": command}
