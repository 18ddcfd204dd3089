"""The CrowBot exercises of 000_32b6074bbd2115c3.txt."""

from __future__ import annotations

import numpy as np

from server.exercises.checks import collisions, mean_abs_error, readings, settling_time_s
from server.exercises.evidence import Evidence
from server.exercises.model import Check, Comparison, Exercise

SETPOINT_M = 0.2  # d_d [m], Table 2
BAND_M = 0.02  # [m] "steady-state error under 2 cm"
STEADY_WINDOW_S = 5.0  # [s] the last seconds of the run count as steady state


def _distance_m(evidence: Evidence) -> tuple[np.ndarray, np.ndarray]:
    times, values = readings(evidence, "Distance", 0.01)
    echo = values > 0  # 0 cm is "no echo", not a distance
    return times[echo], values[echo]


def _settling(evidence: Evidence) -> float:
    return settling_time_s(*_distance_m(evidence), SETPOINT_M, BAND_M)


def _steady_error(evidence: Evidence) -> float:
    times, values = _distance_m(evidence)
    end = evidence.result.duration_s
    return mean_abs_error(values[times >= end - STEADY_WINDOW_S], SETPOINT_M)


def _overshoot(evidence: Evidence) -> float:
    """How much closer than the set point the robot came [m] (0 if it never crossed)."""
    _, values = _distance_m(evidence)
    return float(max(0.0, SETPOINT_M - values.min())) if len(values) else float("inf")


DISTANCE_PID = Exercise(
    id="crowbot_distance_pid",
    title="CrowBot: hold 0.2 m from the wall with a PID",
    robot="crowbot",
    world="wall_approach",
    source="000_32b6074bbd2115c3.txt sections 2.5, 3.3, eq. 3-4, Table 2",
    description=(
        "The CrowBot starts 0.6 m from a wall. Using the ultrasonic Distance topic, hold it "
        "0.2 m from the wall with the PID of eq. 3-4 (Kp = Ki = Kd = 0.4) at 10 Hz, publishing "
        "the linear velocity on Control."
    ),
    duration_s=30.0,
    seeds=(1, 2, 3),
    reference=(("pid_distance", "reference/crowbot_distance_pid.py"),),
    starter=(("pid_distance", "starter/crowbot_distance_pid.py"),),
    checks=(
        Check(
            "settling_time",
            "time until the distance stays within 2 cm of 0.2 m",
            "s",
            Comparison.AT_MOST,
            20.0,
            _settling,
        ),
        Check(
            "steady_state_error",
            "mean |distance - 0.2 m| over the last 5 s",
            "m",
            Comparison.AT_MOST,
            BAND_M,
            _steady_error,
        ),
        Check(
            "overshoot",
            "how much closer than 0.2 m the robot came",
            "m",
            Comparison.AT_MOST,
            0.08,
            _overshoot,
        ),
        Check("collisions", "contacts with the wall", "", Comparison.AT_MOST, 0, collisions),
    ),
)

EXERCISES = (DISTANCE_PID,)
