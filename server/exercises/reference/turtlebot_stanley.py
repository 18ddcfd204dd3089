"""Track the planner's path with the Stanley lateral controller for a differential drive, as
003_4f92d1fa0a49ddae.txt formulates it (section 2.2, eq. 2.8-2.16) and implements it (section
5.9, eq. 5.1-5.7). Reference solution of `turtlebot_stanley`.

Each period, on the current `plan` (nav_msgs/Path, a chain of 5 cm grid-cell centres from the
A* planner) and the localized `pose`:

1. smooth the jagged 8-connected cell chain with a moving average (the thesis's planner gives
   positions only; a staircase would make the heading of the path jump by 45 degrees);
2. T_1 = the point of the path closest to the robot P, T_2 = the point a lookahead distance
   further along it (fig. 5.18);
3. gamma_T = atan2(T_2 - T_1) (5.1), e_gamma = gamma_T - gamma (5.2), |e_y| = |T_1 - P| (5.3),
   its sign from the side of the path P is on (5.4-5.6);
4. gamma_F = e_gamma + arctan(k e_y / v_F), clipped to +-gamma_F,max (2.16);
5. w = f_s k_1 gamma_F (5.7); v_F constant, slowing down near the end of the path and while the
   robot faces away from it (the thesis keeps v_F > 0, which 2.16 needs; here v_F is kept
   above V_SOFT_M_S in the arctan).
"""

import math

import numpy as np

RATE_HZ = 10  # [Hz] f_s, the controller's sample rate
SUBSCRIBE = ["plan", "pose"]

K_STANLEY = 1.5  # [1/s] k of eq. 2.16: how hard the lateral error steers
GAMMA_F_MAX_RAD = 1.2  # [rad] gamma_F,max of eq. 2.16 (0 < gamma_F,max < pi/2)
K1_SMOOTHING = 0.15  # [-] k_1 of eq. 5.7: w = f_s k_1 gamma_F, i.e. 1.5 rad/s per rad
LOOKAHEAD_M = 0.35  # [m] arc length from T_1 to T_2 (fig. 5.18)
SMOOTHING_WINDOW = 7  # [cells] moving average over the planner's cell centres (0.35 m)
CRUISE_M_S = 0.3  # [m/s] v_F on the open path
MIN_SPEED_M_S = 0.05  # [m/s] v_F close to the goal, so the robot still arrives
SLOW_DOWN_M = 0.6  # [m] start slowing this far from the end of the path
STOP_M = 0.05  # [m] stop this close to the end of the path
V_SOFT_M_S = 0.1  # [m/s] lower bound on v_F inside the arctan of eq. 2.16
SEARCH_AHEAD_M = 1.0  # [m] T_1 is searched only this far past the last one (no shortcuts)

_state = {"plan_stamp": None, "path": None, "arc": None, "progress": 0}


def wrap_angle(angle_rad):
    """The angle in (-pi, pi]."""
    wrapped = math.atan2(math.sin(angle_rad), math.cos(angle_rad))
    return math.pi if wrapped == -math.pi else wrapped


def smooth_path(points, window=SMOOTHING_WINDOW):
    """Moving average of an (n, 2) polyline with its end points kept, the window shrinking at
    the ends so the path still starts at the robot and ends at the goal."""
    points = np.asarray(points, dtype=float).reshape(-1, 2)
    n = len(points)
    if n < 3 or window < 2:
        return points.copy()
    half = window // 2
    smoothed = np.empty_like(points)
    for i in range(n):
        reach = min(half, i, n - 1 - i)
        smoothed[i] = points[i - reach : i + reach + 1].mean(axis=0)
    return smoothed


def arc_lengths(points):
    """Cumulative distance along an (n, 2) polyline [m], starting at 0."""
    steps = np.hypot(*np.diff(points, axis=0).T) if len(points) > 1 else np.zeros(0)
    return np.concatenate(([0.0], np.cumsum(steps)))


def closest_point(points, x, y, first=0, last=None):
    """(index of the segment, point) on the polyline nearest to (x, y), looking at segments
    first..last only. A single point is its own nearest point."""
    points = np.asarray(points, dtype=float)
    if len(points) == 1:
        return 0, points[0].copy()
    last = len(points) - 2 if last is None else min(last, len(points) - 2)
    first = min(max(first, 0), last)
    starts, ends = points[first : last + 1], points[first + 1 : last + 2]
    direction = ends - starts
    length_sq = np.maximum((direction**2).sum(axis=1), 1e-12)
    along = np.clip(((np.array([x, y]) - starts) * direction).sum(axis=1) / length_sq, 0.0, 1.0)
    nearest = starts + along[:, None] * direction
    best = int(np.argmin(np.hypot(nearest[:, 0] - x, nearest[:, 1] - y)))
    return first + best, nearest[best]


def point_at_arc(points, arc, distance_m):
    """The point of the polyline `distance_m` along it from its start (clamped to its ends)."""
    if distance_m >= arc[-1]:
        return points[-1].copy()
    if distance_m <= 0.0:
        return points[0].copy()
    i = int(np.searchsorted(arc, distance_m, side="right")) - 1
    fraction = (distance_m - arc[i]) / max(arc[i + 1] - arc[i], 1e-12)
    return points[i] + fraction * (points[i + 1] - points[i])


def stanley_errors(t1, t2, x, y, yaw):
    """(e_y [m], e_gamma [rad]) of eq. 5.1-5.6 for the robot at (x, y, yaw)."""
    gamma_t = math.atan2(t2[1] - t1[1], t2[0] - t1[0])  # (5.1)
    e_gamma = wrap_angle(gamma_t - yaw)  # (5.2)
    abs_e_y = math.hypot(t1[0] - x, t1[1] - y)  # (5.3)
    gamma_l = math.atan2(y - t1[1], x - t1[0])  # (5.4)
    gamma_lt = wrap_angle(gamma_t - gamma_l)  # (5.5), normalized to (-pi, pi]
    e_y = abs_e_y if gamma_lt > 0 else -abs_e_y  # (5.6)
    return e_y, e_gamma


def stanley_heading(e_y, e_gamma, v_f, k=K_STANLEY, gamma_max=GAMMA_F_MAX_RAD):
    """gamma_F of eq. 2.16, clipped to +-gamma_max."""
    gamma_f = e_gamma + math.atan(k * e_y / max(v_f, V_SOFT_M_S))
    return min(max(gamma_f, -gamma_max), gamma_max)


def forward_speed(distance_to_end_m, e_gamma):
    """v_F [m/s]: cruise, ramping down over the last SLOW_DOWN_M, and scaled by cos(e_gamma) so
    the robot turns on the spot rather than driving away when it faces away from the path."""
    if distance_to_end_m < STOP_M:
        return 0.0
    speed = CRUISE_M_S * min(1.0, distance_to_end_m / SLOW_DOWN_M)
    speed = max(speed, MIN_SPEED_M_S)
    return speed * max(0.0, math.cos(e_gamma))


def _pose(message):
    q = message.pose.orientation
    yaw = 2.0 * math.atan2(q.z, q.w)
    return message.pose.position.x, message.pose.position.y, yaw


def step(obs):
    if obs.plan is None or obs.pose is None:
        return 0.0, 0.0
    stamp = (obs.plan.header.stamp.secs, obs.plan.header.stamp.nsecs, len(obs.plan.poses))
    if stamp != _state["plan_stamp"]:  # a new goal: a new path to follow from its start
        cells = [(p.pose.position.x, p.pose.position.y) for p in obs.plan.poses]
        _state["plan_stamp"] = stamp
        _state["path"] = smooth_path(cells) if cells else None
        _state["arc"] = arc_lengths(_state["path"]) if cells else None
        _state["progress"] = 0
    path, arc = _state["path"], _state["arc"]
    if path is None or len(path) < 2:  # the thesis checks for at least two poses
        return 0.0, 0.0
    x, y, yaw = _pose(obs.pose)
    window = int(np.searchsorted(arc, arc[_state["progress"]] + SEARCH_AHEAD_M))
    index, t1 = closest_point(path, x, y, _state["progress"], window)
    _state["progress"] = index
    along_m = arc[index] + math.hypot(*(t1 - path[index]))
    t2 = point_at_arc(path, arc, along_m + LOOKAHEAD_M)
    remaining_m = arc[-1] - along_m
    if math.hypot(t2[0] - t1[0], t2[1] - t1[1]) < 1e-6:  # at the end: aim at the goal itself
        if math.hypot(path[-1][0] - x, path[-1][1] - y) < STOP_M:
            return 0.0, 0.0
        t1, t2 = np.array([x, y]), path[-1]
        remaining_m = math.hypot(t2[0] - x, t2[1] - y)
    e_y, e_gamma = stanley_errors(t1, t2, x, y, yaw)
    v_f = forward_speed(remaining_m, e_gamma)
    gamma_f = stanley_heading(e_y, e_gamma, v_f)
    w = RATE_HZ * K1_SMOOTHING * gamma_f  # (5.7)
    return v_f, w
