"""Reference solution of `crop_row_fuzzy` (not shown to students): follow the left crop row at
0.4 m with a fuzzy controller.

Source: 001_8d7ab1b8a58c0603.txt (the crop-row rover paper). Section 2 (Figures 5-7): the lateral
distance to the LEFT row is the mean of the LiDAR beams of an angle window on the left side, each
projected onto the robot's lateral axis (l_x), then l = l_x cos|e_psi| with e_psi = psi_d - psi.
Section 2.2 (Figures 10-13): a scikit-fuzzy Mamdani controller, input l over 0..0.8 m with sets
LLL, LL, L, C (peak 0.4 m), R, RR, RRR; output u with sets TRR, TR, Z, TL, TLL (negative u turns
left); seven rules; centroid defuzzification. Section 2.3: at a row end the number of reflected
beams drops; the robot turns until the beams return and follows the next row.

The paper gives no membership parameters, only eight input -> output pairs (section 2.2, Figures
12-13). The sets below were fitted to them (Nelder-Mead over the peaks of a partition of unity on
the input and mirrored triangles on the output, then rounded to mm and 0.1):

| l [m] | published u | this file | set(s) firing |
|-------|-------------|-----------|---------------|
| 0.15  |  72.87      |  72.9     | LLL, LL       |
| 0.20  |  56.37      |  56.4     | LL (mostly)   |
| 0.35  |  36.71      |  36.4     | L, C          |
| 0.40  |  "about 0"  |   0.0     | C             |
| 0.50  | -33.63      | -33.5     | C, R          |  the text misprints this distance as 0.6
| 0.60  | -54.79      | -54.8     | RR (mostly)   |
| 0.70  | -82.82      | -82.7     | RRR (mostly)  |
| 0.80  | -83.24      | -83.2     | RRR           |

Design choices the paper leaves open (documented assumptions):

- Angle window. LiDAR angles follow Figure 5 (0 at the rear, left side (0, pi), robot direction =
  pi - lidar angle). The window runs from `WINDOW_LOW_RAD` to `WINDOW_HIGH_RAD`, a little behind
  the robot's left (pi/2) to well ahead of it. A window centred on pi/2 would make l independent
  of the heading to first order, and a controller of l alone then oscillates without damping
  (the rover's turn rate integrates into heading, which integrates into l). Looking ahead makes
  l read shorter while the rover points towards the row: a look-ahead that damps the loop.
- Returns farther than `MAX_LATERAL_M` to the side passed through a gap between plants and hit
  the next row; they are dropped, as are beams with no return (range 0.0).
- The beams reflect from the near face of the plants, so l is short of the row's centre line by
  about a plant radius; `ROW_FACE_OFFSET_M` is added before the fuzzy controller, so the rover
  holds 0.4 m from the plants' centres (the 0.06 m radius plants of the `crop_rows` world read
  ~0.04 m short: beams hit them obliquely).
- Heading guard. Far from the row's direction the look-ahead turns against us: pointing more
  than ~25 deg away from the row, the window's forward beams run nearly along it and are dropped
  as too far, the remaining rear ones and cos|e_psi| make l read short, and the controller turns
  the rover further away. So while following, u may not turn the heading past
  `HEADING_LIMIT_RAD` from psi_d (this only acts in the first seconds of a start far from
  0.4 m; otherwise the fuzzy output goes out as it is).
- psi_d is the yaw at the first reading (the robot starts aligned with the rows, Figure 9) and
  turns by pi at each lane change. The IMU's drift is ignored, as in the paper.
- Row end (section 2.3): the rover follows the LEFT row. When the window holds fewer than
  `ROW_END_BEAMS` returns for `ROW_END_CONFIRM_S`, the row is over. The next lane lies on the
  side of the row just followed, so the first turn is to the LEFT, around the row's end, into the
  lane beyond it, where that same row is again on the left. At the far end the next lane lies on
  the right, so the turns alternate (serpentine: left, right, left, ...). A turn is an arc of
  radius `TURN_RADIUS_M` (half the row spacing) through pi, measured with the IMU yaw (the paper
  calls its maneuver open loop). Ending the arc on the beam count alone, as the paper words it,
  overshoots: after half a circle the rover stands at the lane's mouth, where the window still
  sees almost no plants. So after the arc the rover holds the new heading until the count is
  back above `ROW_FOUND_BEAMS` for `ROW_FOUND_CONFIRM_S`, then follows the row again.
"""

from __future__ import annotations

import contextlib
import functools
import math
import warnings

import numpy as np
import skfuzzy as fuzz
from skfuzzy import control as ctrl

RATE_HZ = 10  # [Hz] faster than the ~7 Hz scan, so a new scan waits at most 0.1 s
SUBSCRIBE = ["scan", "psi"]

# Angle window and beam filter (LiDAR angles, Figure 5: robot direction = pi - lidar angle).
WINDOW_LOW_RAD = math.pi / 2 - 0.35  # [rad] 20 deg behind the robot's left
WINDOW_HIGH_RAD = math.pi / 2 + 0.85  # [rad] 49 deg ahead of it: the look-ahead that damps
MAX_LATERAL_M = 0.8  # [m] the fuzzy universe and the row spacing; farther is the next row
ROW_FACE_OFFSET_M = 0.04  # [m] beams stop on the plants' near face, short of the row centre

# Row ends (section 2.3).
ROW_END_BEAMS = 6  # [1] fewer returns: no row beside (~50 along a row, >= 15 at its gaps)
ROW_END_CONFIRM_S = 1.0  # [s] several scans, so one odd scan does not end a row
ROW_FOUND_BEAMS = 15  # [1] this many returns again: the rover is beside the next row
ROW_FOUND_CONFIRM_S = 0.5  # [s]
MIN_FOLLOW_S = 3.0  # [s] after entering a lane, before a row end may be declared
CRUISE_M_S = 0.15  # [m/s] the rover's speed (server/sim/robots/crop_rover.py)
MAX_TURN_RAD_S = 1.2  # [rad/s] turn rate at |u| = 100
TURN_RADIUS_M = 0.4  # [m] half the row spacing: a half circle shifts one lane
TURN_U = 100.0 * CRUISE_M_S / TURN_RADIUS_M / MAX_TURN_RAD_S  # [1] ~31 for a 0.4 m arc
TURN_EARLY_RAD = 0.05  # [rad] stop the arc this much short of pi: the motors lag ~0.08 s
HEADING_GAIN_U_PER_RAD = 100.0  # [1/rad] heading hold: entering a lane, gaps, the guard
HEADING_LIMIT_RAD = 0.4  # [rad] 23 deg: past ~25 deg away from the row, l reads short
U_LIMIT = 100.0  # [1]

# Fuzzy sets (fitted, see the table above). Input l [m]: peaks of LLL..RRR, a partition of unity.
L_PEAKS_M = (0.132, 0.204, 0.342, 0.400, 0.521, 0.601, 0.701)
# Output u [1], positive = turn right: triangles (foot, peak, foot); the left turns mirror them.
U_ZERO_HALF_WIDTH = 42.8
U_TURN_RIGHT = (32.6, 54.8, 77.0)  # TR
U_TURN_RIGHT_HARD = (61.3, 91.1, 97.3)  # TRR
L_RANGE_M = (0.0, 0.8)  # [m] input universe
TARGET_L_M = 0.4  # [m] the centre set C's peak: where a following rover's l stays
U_RANGE = (-100.0, 100.0)  # [1] output universe

# The curve u(l) is computed a stretch of CURVE_CHUNK_POINTS millimetres at a time, where l first
# falls: a run visits a few centimetres around 0.4 m, and the whole curve costs ~0.9 s of every
# node's start (skfuzzy's centroid is a Python loop over the 2001-point output universe, ~1.3 ms a
# point), where the stretches a run needs cost ~25 ms each. skfuzzy computes every point on its
# own, so a stretch's values are bit for bit those of the whole curve (tests compare them).
CURVE_CHUNK_POINTS = 20  # [1] millimetre points computed together
_fuzzy: ctrl.ControlSystemSimulation | None = None
_curve_u = None  # u [1] at every millimetre of the input universe, NaN until computed


@functools.cache  # every step interpolates on it
def _l_universe() -> np.ndarray:
    return np.round(np.arange(L_RANGE_M[0], L_RANGE_M[1] + 0.0005, 0.001), 3)  # [m] 1 mm


def build_fuzzy() -> ctrl.ControlSystemSimulation:
    """The paper's controller (section 2.2): 7 input sets, 5 output sets, 7 rules, centroid."""
    l_universe = _l_universe()
    u_universe = np.round(np.arange(U_RANGE[0], U_RANGE[1] + 0.05, 0.1), 1)
    distance = ctrl.Antecedent(l_universe, "l")
    action = ctrl.Consequent(u_universe, "u", defuzzify_method="centroid")
    p1, p2, p3, p4, p5, p6, p7 = L_PEAKS_M
    distance["LLL"] = fuzz.trapmf(l_universe, [L_RANGE_M[0], L_RANGE_M[0], p1, p2])
    distance["LL"] = fuzz.trimf(l_universe, [p1, p2, p3])
    distance["L"] = fuzz.trimf(l_universe, [p2, p3, p4])
    distance["C"] = fuzz.trimf(l_universe, [p3, p4, p5])
    distance["R"] = fuzz.trimf(l_universe, [p4, p5, p6])
    distance["RR"] = fuzz.trimf(l_universe, [p5, p6, p7])
    distance["RRR"] = fuzz.trapmf(l_universe, [p6, p7, L_RANGE_M[1], L_RANGE_M[1]])
    zero, right, hard = U_ZERO_HALF_WIDTH, U_TURN_RIGHT, U_TURN_RIGHT_HARD
    action["TRR"] = fuzz.trimf(u_universe, list(hard))
    action["TR"] = fuzz.trimf(u_universe, list(right))
    action["Z"] = fuzz.trimf(u_universe, [-zero, 0.0, zero])
    action["TL"] = fuzz.trimf(u_universe, [-right[2], -right[1], -right[0]])
    action["TLL"] = fuzz.trimf(u_universe, [-hard[2], -hard[1], -hard[0]])
    rules = [
        ctrl.Rule(distance["LLL"], action["TRR"]),  # rule1
        ctrl.Rule(distance["LL"], action["TR"]),  # rule2
        ctrl.Rule(distance["L"], action["TR"]),  # rule3
        ctrl.Rule(distance["C"], action["Z"]),  # rule4
        ctrl.Rule(distance["R"], action["TL"]),  # rule5
        ctrl.Rule(distance["RR"], action["TL"]),  # rule6
        ctrl.Rule(distance["RRR"], action["TLL"]),  # rule7
    ]
    return ctrl.ControlSystemSimulation(ctrl.ControlSystem(rules))


@contextlib.contextmanager
def _quiet_skfuzzy():
    """skfuzzy 0.5.0 hands np.maximum its `out` positionally, which numpy 2 deprecates; the
    result is right, the warning only noise in the student's log."""
    with warnings.catch_warnings():
        warnings.filterwarnings(
            "ignore", "Passing more than 2 positional arguments", DeprecationWarning
        )
        yield


def fuzzy_output(l_m: float) -> float:
    """u straight from a fresh ControlSystem (slow: ~20 ms; `control_action` is the fast path)."""
    fuzzy = build_fuzzy()
    fuzzy.input["l"] = min(max(float(l_m), L_RANGE_M[0]), L_RANGE_M[1])
    with _quiet_skfuzzy():
        fuzzy.compute()
    return float(fuzzy.output["u"])


def _computed_curve(first: int, last: int) -> np.ndarray:
    """u at every millimetre, with at least points `first`..`last` of the universe computed."""
    global _fuzzy, _curve_u
    l_m = _l_universe()
    if _curve_u is None:
        _fuzzy = build_fuzzy()
        _curve_u = np.full(l_m.size, np.nan)
    for chunk in range(first // CURVE_CHUNK_POINTS, last // CURVE_CHUNK_POINTS + 1):
        # Every stretch the same length (the last one ends at 0.8 m): skfuzzy warns when an
        # input's shape changes between computes.
        start = min(chunk * CURVE_CHUNK_POINTS, l_m.size - CURVE_CHUNK_POINTS)
        points = slice(start, start + CURVE_CHUNK_POINTS)
        if np.isnan(_curve_u[points]).any():
            _fuzzy.input["l"] = l_m[points]
            with _quiet_skfuzzy():
                _fuzzy.compute()
            _curve_u[points] = np.asarray(_fuzzy.output["u"], dtype=np.float64)
    return _curve_u


def control_action(l_m: float) -> float:
    """The fuzzy control word u for a lateral distance `l_m` [m] to the left row (clipped to
    0..0.8 m); positive turns right, away from the row.

    A single compute() costs 4-15 ms, most of it skfuzzy's rule-graph bookkeeping (networkx); with
    one input the curve is all there is to know, so this interpolates it between the two
    millimetres around l (error < 0.01), computing their stretch the first time."""
    l_table = _l_universe()
    clipped_m = min(max(float(l_m), L_RANGE_M[0]), L_RANGE_M[1])
    below = min(int(np.searchsorted(l_table, clipped_m, side="right")) - 1, l_table.size - 2)
    u_table = _computed_curve(max(below, 0), below + 1)
    return float(np.interp(l_m, l_table, u_table))


def _window_projections(ranges, angle_min: float, angle_increment: float) -> np.ndarray:
    """Lateral projections [m] of the valid beams in the left window."""
    ranges_m = np.asarray(ranges, dtype=np.float64)
    angles_rad = angle_min + angle_increment * np.arange(ranges_m.size)
    in_window = (angles_rad >= WINDOW_LOW_RAD) & (angles_rad <= WINDOW_HIGH_RAD)
    # Robot direction pi - a, so the lateral (leftward) part of a beam is r sin(pi - a) = r sin a.
    lateral_m = ranges_m * np.sin(angles_rad)
    valid = in_window & np.isfinite(ranges_m) & (ranges_m > 0.0) & (lateral_m <= MAX_LATERAL_M)
    return lateral_m[valid]


def window_returns(ranges, angle_min: float, angle_increment: float) -> int:
    """How many beams of the left window reflected from the row (section 2.3's beam count)."""
    return int(_window_projections(ranges, angle_min, angle_increment).size)


def lateral_distance(
    ranges, angle_min: float, angle_increment: float, psi: float, psi_d: float
) -> float | None:
    """l = l_x cos|e_psi| [m] to what the left window sees (section 2, Figure 7); None if no beam
    of the window returned."""
    projections_m = _window_projections(ranges, angle_min, angle_increment)
    if projections_m.size == 0:
        return None
    heading_error_rad = _wrap(psi_d - psi)
    return float(np.mean(projections_m) * math.cos(abs(heading_error_rad)))


def _wrap(angle_rad: float) -> float:
    return math.atan2(math.sin(angle_rad), math.cos(angle_rad))


def _clip_u(u: float) -> float:
    return min(max(u, -U_LIMIT), U_LIMIT)


def _heading_guard(u: float, heading_rad: float) -> float:
    """Keep the heading within HEADING_LIMIT_RAD of the row's: beyond it the window misreads l."""
    if heading_rad < -HEADING_LIMIT_RAD:  # turned right, away from the row: no more right
        return min(u, HEADING_GAIN_U_PER_RAD * (heading_rad + HEADING_LIMIT_RAD))
    if heading_rad > HEADING_LIMIT_RAD:  # turned left, towards the row: no more left
        return max(u, HEADING_GAIN_U_PER_RAD * (heading_rad - HEADING_LIMIT_RAD))
    return u


class RowFollower:
    """The row-following state machine: follow -> turn -> enter -> follow (module docstring)."""

    def __init__(self) -> None:
        self.phase = "follow"
        self.phase_started_s = 0.0
        self.psi_d: float | None = None
        self.turn_direction = 1.0  # +1: the next turn is to the left (counter-clockwise)
        self.turned_rad = 0.0
        self.last_psi: float | None = None
        self.count_since_s: float | None = None  # since when the count is past the threshold
        self.lane_changes = 0

    def _enter(self, phase: str, time_s: float) -> None:
        self.phase = phase
        self.phase_started_s = time_s
        self.count_since_s = None

    def _held(self, condition: bool, time_s: float, needed_s: float) -> bool:
        """True once `condition` has held for `needed_s` [s]."""
        if not condition:
            self.count_since_s = None
            return False
        if self.count_since_s is None:
            self.count_since_s = time_s
        return time_s - self.count_since_s >= needed_s

    def step(self, scan, psi: float, time_s: float) -> float:
        if self.psi_d is None:
            self.psi_d = psi
            self.phase_started_s = time_s
        if self.last_psi is None:
            self.last_psi = psi
        self.turned_rad += _wrap(psi - self.last_psi)
        self.last_psi = psi
        heading_hold_u = _clip_u(HEADING_GAIN_U_PER_RAD * _wrap(psi - self.psi_d))

        if self.phase == "turn":
            if self.turn_direction * self.turned_rad >= math.pi - TURN_EARLY_RAD:
                self.psi_d = _wrap(self.psi_d + math.pi)
                self.turn_direction = -self.turn_direction
                self.lane_changes += 1
                self._enter("enter", time_s)
                return _clip_u(HEADING_GAIN_U_PER_RAD * _wrap(psi - self.psi_d))
            return -self.turn_direction * TURN_U  # negative u turns left

        if scan is None:
            return heading_hold_u
        returns = window_returns(scan.ranges, scan.angle_min, scan.angle_increment)
        if self.phase == "enter":
            if self._held(returns >= ROW_FOUND_BEAMS, time_s, ROW_FOUND_CONFIRM_S):
                self._enter("follow", time_s)
            return heading_hold_u

        # phase == "follow"
        settled = time_s - self.phase_started_s >= MIN_FOLLOW_S
        if self._held(returns < ROW_END_BEAMS, time_s, ROW_END_CONFIRM_S) and settled:
            self._enter("turn", time_s)
            self.turned_rad = 0.0
            return -self.turn_direction * TURN_U
        l_m = lateral_distance(scan.ranges, scan.angle_min, scan.angle_increment, psi, self.psi_d)
        if l_m is None:
            return heading_hold_u  # a gap in the row: keep the heading
        return _heading_guard(control_action(l_m + ROW_FACE_OFFSET_M), _wrap(psi - self.psi_d))


_follower = RowFollower()


def setup(info=None) -> None:
    """Build the fuzzy controller and the curve around 0.4 m before the first step."""
    control_action(TARGET_L_M)


def reset() -> None:
    """Forget the run: the next step() starts a new one (for tests running several)."""
    global _follower
    _follower = RowFollower()


def step(obs):
    if obs.psi is None:
        return {"u": 0.0}  # straight ahead until the IMU's first yaw sets the row heading
    return {"u": _follower.step(obs.scan, obs.psi.data, obs.time)}
