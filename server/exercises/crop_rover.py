"""The crop-row exercise of 001_8d7ab1b8a58c0603.txt: fuzzy row following with a LiDAR and an
IMU, from the paper's three starting offsets, through three paths (section 2.3, Fig. 15-16)."""

from __future__ import annotations

import numpy as np

from server.exercises.checks import collisions
from server.exercises.evidence import Evidence
from server.exercises.model import Check, Comparison, Exercise

LEFT_ROW_Y_M = 1.6  # [m] the left row of the first lane (crop_rows.toml)
ROW_START_X_M, ROW_END_X_M = 1.5, 6.0  # [m] first and last plant of every row
TARGET_M = 0.4  # [m] the centre set C of the paper's input (Figure 10)
SETTLE_BAND_M = 0.05  # [m]
LANE_CENTRES_Y_M = (1.2, 2.0, 2.8, 3.6)  # [m] lanes between the rows, 0.8 m apart
LANE_HALF_WIDTH_M = 0.2  # [m] inside this band of a lane centre the rover is in that lane
PATH_LENGTH_M = 3.0  # [m] of travel along x inside a lane that counts as driving a path


def _first_lane(evidence: Evidence) -> tuple[np.ndarray, np.ndarray]:
    """(times, distance to the left row) while the rover drives the first lane."""
    inside = (evidence.pose_x >= ROW_START_X_M) & (evidence.pose_x <= ROW_END_X_M - 0.3)
    inside &= evidence.pose_y < LANE_CENTRES_Y_M[0] + 0.4
    first = np.flatnonzero(inside)
    if not len(first):
        return np.zeros(0), np.zeros(0)
    # Only the first stretch: stop at the first gap in `inside` (the row end turn).
    stretch = first[: np.argmax(np.diff(first) > 1) + 1] if np.any(np.diff(first) > 1) else first
    return evidence.pose_t[stretch], LEFT_ROW_Y_M - evidence.pose_y[stretch]


def _settling(evidence: Evidence) -> float:
    times, distance = _first_lane(evidence)
    outside = np.abs(distance - TARGET_M) > SETTLE_BAND_M
    if not len(times) or outside[-1]:
        return float("inf")
    late = np.flatnonzero(outside)
    return float(times[late[-1] + 1] - times[0]) if len(late) else 0.0


def _rms_after_settling(evidence: Evidence) -> float:
    times, distance = _first_lane(evidence)
    settled_at = _settling(evidence)
    if not np.isfinite(settled_at):
        return float("inf")
    after = times >= times[0] + settled_at
    return float(np.sqrt(np.mean((distance[after] - TARGET_M) ** 2)))


def _paths(evidence: Evidence) -> float:
    """Lanes in which the rover drove at least PATH_LENGTH_M along the rows."""
    driven = 0
    for centre in LANE_CENTRES_Y_M:
        in_lane = np.abs(evidence.pose_y - centre) < LANE_HALF_WIDTH_M
        in_lane &= (evidence.pose_x > ROW_START_X_M) & (evidence.pose_x < ROW_END_X_M)
        if in_lane.sum() > 1 and np.ptp(evidence.pose_x[in_lane]) >= PATH_LENGTH_M:
            driven += 1
    return float(driven)


CROP_ROW_FUZZY = Exercise(
    id="crop_row_fuzzy",
    title="Crop rover: follow the left row with a fuzzy controller, through three paths",
    robot="crop_rover",
    world="crop_rows",
    source="001_8d7ab1b8a58c0603.txt sections 2-2.3, Figures 5-16",
    description=(
        "Keep the rover 0.4 m from the crop row on its left: measure the lateral distance from "
        "a LiDAR angle window corrected with the IMU yaw (l = l_x cos|e_psi|), feed it to a "
        "scikit-fuzzy controller with the paper's seven rules, and publish the control word u "
        "(negative = left). At a row end (few reflected beams) turn into the next path; drive "
        "three paths."
    ),
    duration_s=120.0,
    seeds=(1,),
    # The paper's three runs started 0.57, 0.4 and 0.28 m from the left row (section 2.3).
    starts=tuple((1.4, LEFT_ROW_Y_M - offset, 0.0) for offset in (0.57, 0.40, 0.28)),
    reference=(("fuzzy_follower", "reference/crop_row_fuzzy.py"),),
    starter=(("fuzzy_follower", "starter/crop_row_fuzzy.py"),),
    leaderboard_check="settling_time",
    checks=(
        Check(
            "settling_time",
            "time in the first path until the distance to the left row stays within 5 cm of 0.4 m",
            "s",
            Comparison.AT_MOST,
            10.0,
            _settling,
        ),
        Check(
            "lateral_rms",
            "RMS of (distance to the left row - 0.4 m) along the first path after settling",
            "m",
            Comparison.AT_MOST,
            0.05,
            _rms_after_settling,
        ),
        Check(
            "paths",
            "paths (lanes) driven at least 3 m along the rows",
            "",
            Comparison.AT_LEAST,
            3,
            _paths,
        ),
        Check(
            "collisions",
            "contacts with plants",
            "",
            Comparison.AT_MOST,
            0,
            collisions,
        ),
    ),
)

EXERCISES = (CROP_ROW_FUZZY,)
