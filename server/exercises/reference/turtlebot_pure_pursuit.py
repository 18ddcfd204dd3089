"""Track the planner's path with pure pursuit, for comparison with the Stanley controller of
turtlebot_stanley.py (003_4f92d1fa0a49ddae.txt section 2.2 names pure pursuit [1] as the
classic geometric tracker; the thesis compares its Stanley controller with Nav2's DWB in
section 6). Not part of the graded reference of `turtlebot_stanley`.

Pure pursuit (Coulter, "Implementation of the Pure Pursuit Path Tracking Algorithm", CMU-RI-TR-
92-01, 1992): steer along the circular arc through the robot and a goal point one lookahead
distance L ahead on the path. With alpha the bearing of that point from the robot's heading, the
arc's curvature is kappa = 2 sin(alpha) / L, and a differential drive turns at w = v kappa.
"""

import math

import numpy as np

RATE_HZ = 10  # [Hz]
SUBSCRIBE = ["plan", "pose"]

LOOKAHEAD_M = 0.25  # [m] L: longer cuts the door corners into the walls
SMOOTHING_WINDOW = 7  # [cells] moving average over the planner's cell centres (0.35 m)
CRUISE_M_S = 0.3  # [m/s]
MIN_SPEED_M_S = 0.05  # [m/s] close to the goal, so the robot still arrives
SLOW_DOWN_M = 0.6  # [m] start slowing this far from the end of the path
STOP_M = 0.05  # [m]
TURN_IN_PLACE_RAD = math.pi / 2  # [rad] beyond this bearing, turn on the spot first
TURN_GAIN = 1.5  # [rad/s per rad] the on-the-spot turn rate
MAX_TURN_RAD_S = 1.8  # [rad/s]
SEARCH_AHEAD_M = 1.0  # [m] the closest point is searched only this far past the last one

_state = {"plan_stamp": None, "path": None, "arc": None, "progress": 0}


def smooth_path(points, window=SMOOTHING_WINDOW):
    """Moving average of an (n, 2) polyline, the window shrinking at the ends so the path keeps
    its end points."""
    points = np.asarray(points, dtype=float).reshape(-1, 2)
    n = len(points)
    if n < 3 or window < 2:
        return points.copy()
    smoothed = np.empty_like(points)
    for i in range(n):
        reach = min(window // 2, i, n - 1 - i)
        smoothed[i] = points[i - reach : i + reach + 1].mean(axis=0)
    return smoothed


def pursuit_curvature(x, y, yaw, goal_x, goal_y, lookahead_m):
    """kappa [1/m] of the arc from the robot at (x, y, yaw) through the goal point."""
    alpha = math.atan2(goal_y - y, goal_x - x) - yaw
    return 2.0 * math.sin(alpha) / max(lookahead_m, 1e-6)


def _closest_index(path, x, y, first, last):
    distances = np.hypot(path[first : last + 1, 0] - x, path[first : last + 1, 1] - y)
    return first + int(np.argmin(distances))


def step(obs):
    if obs.plan is None or obs.pose is None:
        return 0.0, 0.0
    stamp = (obs.plan.header.stamp.secs, obs.plan.header.stamp.nsecs, len(obs.plan.poses))
    if stamp != _state["plan_stamp"]:
        cells = [(p.pose.position.x, p.pose.position.y) for p in obs.plan.poses]
        _state.update(plan_stamp=stamp, progress=0, path=None, arc=None)
        if cells:
            path = smooth_path(cells)
            steps = np.hypot(*np.diff(path, axis=0).T) if len(path) > 1 else np.zeros(0)
            _state.update(path=path, arc=np.concatenate(([0.0], np.cumsum(steps))))
    path, arc = _state["path"], _state["arc"]
    if path is None:
        return 0.0, 0.0
    q = obs.pose.pose.orientation
    x, y, yaw = obs.pose.pose.position.x, obs.pose.pose.position.y, 2.0 * math.atan2(q.z, q.w)
    last = int(np.searchsorted(arc, arc[_state["progress"]] + SEARCH_AHEAD_M))
    index = _closest_index(path, x, y, _state["progress"], min(last, len(path) - 1))
    _state["progress"] = index
    goal_index = min(int(np.searchsorted(arc, arc[index] + LOOKAHEAD_M)), len(path) - 1)
    goal_x, goal_y = path[goal_index]
    to_end_m = math.hypot(path[-1][0] - x, path[-1][1] - y)
    if to_end_m < STOP_M:
        return 0.0, 0.0
    bearing = math.atan2(goal_y - y, goal_x - x) - yaw
    bearing = math.atan2(math.sin(bearing), math.cos(bearing))
    if abs(bearing) > TURN_IN_PLACE_RAD:
        return 0.0, max(-MAX_TURN_RAD_S, min(MAX_TURN_RAD_S, TURN_GAIN * bearing))
    speed = max(MIN_SPEED_M_S, CRUISE_M_S * min(1.0, (arc[-1] - arc[index]) / SLOW_DOWN_M))
    distance = max(math.hypot(goal_x - x, goal_y - y), 1e-6)
    w = speed * pursuit_curvature(x, y, yaw, goal_x, goal_y, distance)
    return speed, max(-MAX_TURN_RAD_S, min(MAX_TURN_RAD_S, w))
