"""Hold the CrowBot 0.2 m from the wall with a PID controller.

000_32b6074bbd2115c3.txt section 2.5, eq. 3-4 and Table 2: e(t) = d_d - d_r(t), d_d = 0.2 m, and
u_c(t) = Kp e + Ki integral(e) + Kd de/dt with Kp = Ki = Kd = 0.4, at 10 Hz. The robot starts
0.6 m from the wall. `Distance` is the ultrasonic range in whole centimetres (0 = no echo);
return the linear velocity [m/s] as (v, 0.0).
"""

RATE_HZ = 10  # [Hz] the paper's control rate
SUBSCRIBE = ["Distance"]

KP, KI, KD = 0.4, 0.4, 0.4  # Table 2
SETPOINT_M = 0.2  # d_d [m]


def step(obs):
    if obs.Distance is None or obs.Distance.data == 0:
        return (0.0, 0.0)
    distance_m = obs.Distance.data / 100.0
    error_m = distance_m - SETPOINT_M
    # TODO: add the integral and derivative terms of eq. 4.
    command = 0.0 * error_m  # TODO: use KP, KI and KD
    return (command, 0.0)
