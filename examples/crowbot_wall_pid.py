"""Hold the CrowBot 0.2 m from a wall with the PID of 000_32b6074bbd2115c3.txt eq. 3-4.

Kp = Ki = Kd = 0.4 (Table 2), 10 Hz, starting 0.6 m away, driving the simulator directly (no
sandbox, no run engine): a check that the simulated robot can repeat the paper's experiment.

    python examples/crowbot_wall_pid.py
"""

from __future__ import annotations

from sandbox.msgs.geometry_msgs import Twist, Vector3
from server.sim import Simulation

KP, KI, KD = 0.4, 0.4, 0.4  # Table 2
SETPOINT_M = 0.2  # d_d [m]
PERIOD_S = 0.1  # 10 Hz


def main() -> None:
    sim = Simulation("crowbot", "wall_approach", seed=0)
    integral = 0.0
    previous_error = None
    for step in range(150):  # 15 s
        distance_m = sim.read("Distance").data / 100.0
        # eq. 3 as the paper writes it is d_d - d_r; the robot must drive forward when it is
        # too far, so the command uses the opposite sign.
        error = distance_m - SETPOINT_M
        integral += error * PERIOD_S
        derivative = 0.0 if previous_error is None else (error - previous_error) / PERIOD_S
        previous_error = error
        command = KP * error + KI * integral + KD * derivative
        sim.apply("Control", Twist(linear=Vector3(x=command)))
        sim.step(PERIOD_S)
        if step % 10 == 0:
            print(f"t={sim.time_s:5.1f} s  distance={distance_m:.2f} m  u={command:+.3f} m/s")
    print(f"final distance {sim.read('Distance').data} cm, contacts {sim.state.contact_count}")


if __name__ == "__main__":
    main()
