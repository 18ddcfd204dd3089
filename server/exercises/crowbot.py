"""The CrowBot exercises of 000_32b6074bbd2115c3.txt."""

from __future__ import annotations

import itertools

import numpy as np

from server.exercises.checks import collisions, mean_abs_error, readings, settling_time_s
from server.exercises.evidence import Evidence
from server.exercises.model import Check, Comparison, Exercise, ScriptEvent
from server.runs.commands import Button, Light

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
    leaderboard_check="settling_time",
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

# The lamp of light_arena starts 0.6 m to the robot's left and moves three times, each time to
# where the tracker can still see it (within ~75 degrees of where it faces).
LAMP_START = (1.0, 1.6)  # [m] as in the world file
LAMP_MOVES = ((8.0, (1.52, 1.30)), (16.0, (1.52, 0.70)), (24.0, (1.42, 1.42)))  # [s], [m]
SETTLE_AFTER_MOVE_S = 5.0  # [s] "within 5 s after each move"
MAX_HEADING_ERROR_DEG = 15.0


def _heading_error_deg(evidence: Evidence) -> float:
    """Worst |heading error to the lamp| 5 s after the start and after each move [deg]."""
    worst = 0.0
    for moved_at, (lamp_x, lamp_y) in ((0.0, LAMP_START), *LAMP_MOVES):
        at = np.searchsorted(evidence.pose_t, moved_at + SETTLE_AFTER_MOVE_S)
        if at >= len(evidence.pose_t):
            return float("inf")
        bearing = np.arctan2(lamp_y - evidence.pose_y[at], lamp_x - evidence.pose_x[at])
        error = np.angle(np.exp(1j * (bearing - evidence.pose_yaw[at])))
        worst = max(worst, abs(float(np.degrees(error))))
    return worst


LIGHT_TRACKING = Exercise(
    id="crowbot_light_tracking",
    title="CrowBot: turn to face a moving light",
    robot="crowbot",
    world="light_arena",
    source="000_32b6074bbd2115c3.txt sections 2.5, 3.4, eq. 5, Table 2",
    description=(
        "A lamp stands to the CrowBot's left and is moved three times. Turn in place to face it "
        "with the proportional controller of eq. 5 (K_w = 2) on the two Light readings."
    ),
    duration_s=32.0,
    seeds=(1, 2),
    spawn="centre",
    script=tuple(ScriptEvent(t, Light(x, y, name="lamp")) for t, (x, y) in LAMP_MOVES),
    reference=(("light_tracker", "reference/crowbot_light_tracking.py"),),
    starter=(("light_tracker", "starter/crowbot_light_tracking.py"),),
    leaderboard_check="heading_error",
    checks=(
        Check(
            "heading_error",
            "worst heading error to the lamp 5 s after the start and after each move",
            "deg",
            Comparison.AT_MOST,
            MAX_HEADING_ERROR_DEG,
            _heading_error_deg,
        ),
    ),
)

LOGGER_RATE_HZ = 10.0  # [Hz] the rate the exercise asks for
LOGGER_DURATION_S = 15.0  # [s] as the paper's 15 s button recording (Fig. 10)


def _figure_saved(evidence: Evidence) -> float:
    pngs = [p for p in evidence.artifacts("data_logger") if p.suffix == ".png"]
    return float(any(p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" for p in pngs))


def _coverage(evidence: Evidence) -> float:
    """Rows of samples.csv over the rows the rate and duration call for (1.0 = all)."""
    csv = [p for p in evidence.artifacts("data_logger") if p.name == "samples.csv"]
    if not csv:
        return 0.0
    rows = [line for line in csv[0].read_text().splitlines()[1:] if line.strip()]
    return len(rows) / (LOGGER_RATE_HZ * LOGGER_DURATION_S)


def _buttons_seen(evidence: Evidence) -> float:
    """Button presses (rising edges) in samples.csv: the script presses it twice."""
    csv = [p for p in evidence.artifacts("data_logger") if p.name == "samples.csv"]
    if not csv:
        return 0.0
    states = [line.split(",")[1] for line in csv[0].read_text().splitlines()[1:] if line.strip()]
    return float(sum(1 for a, b in itertools.pairwise(states) if a == "0" and b == "1"))


DATA_LOGGER = Exercise(
    id="crowbot_data_logger",
    title="CrowBot: record the sensors and plot them",
    robot="crowbot",
    world="line_track",
    source="000_32b6074bbd2115c3.txt section 3.2, Fig. 10-13",
    description=(
        "Record the Button, Distance, Light and Line readings at 10 Hz for the whole run into "
        "samples.csv, then plot them into readings.png, as the paper's data-acquisition "
        "programs do. The button is pressed twice during the run."
    ),
    duration_s=LOGGER_DURATION_S,
    seeds=(1,),
    script=(
        ScriptEvent(3.0, Button(True)),
        ScriptEvent(4.0, Button(False)),
        ScriptEvent(9.0, Button(True)),
        ScriptEvent(10.5, Button(False)),
    ),
    reference=(("data_logger", "reference/crowbot_data_logger.py"),),
    starter=(("data_logger", "starter/crowbot_data_logger.py"),),
    leaderboard_check="coverage",
    checks=(
        Check("figure_saved", "a PNG figure was saved", "", Comparison.AT_LEAST, 1, _figure_saved),
        Check(
            "coverage",
            "samples.csv rows / (10 Hz x 15 s)",
            "",
            Comparison.AT_LEAST,
            0.95,
            _coverage,
        ),
        Check(
            "button_presses",
            "button presses visible in samples.csv",
            "",
            Comparison.AT_LEAST,
            2,
            _buttons_seen,
        ),
    ),
)

EXERCISES = (DISTANCE_PID, LIGHT_TRACKING, DATA_LOGGER)
