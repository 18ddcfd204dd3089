"""The Stanley lateral controller as the thesis builds it for Nav2 (003_4f92d1fa0a49ddae.txt
section 5.9): a service server the controller server calls every control period. Reference
solution of `turtlebot_stanley_ros2`.

The controller server (the lab's built-in `nav2`, standing in for the thesis's C++ plugin whose
computeVelocityCommands() calls this service) sends the robot's pose and the planner's path; the
answer is the velocities it publishes on cmd_vel. Each call:

1. smooth the jagged 8-connected cell chain with a moving average (the planner gives positions
   only; a staircase would make the heading of the path jump by 45 degrees);
2. check the path has at least two poses (as the thesis does);
3. T_1 = the point of the path closest to the robot P, T_2 = the point a lookahead distance
   further along it (fig. 5.18), published on `lookahead` as the thesis's node publishes it
   for RViz (the 3D view draws it);
4. gamma_T = atan2(T_2 - T_1) (5.1), e_gamma = gamma_T - gamma (5.2), |e_y| = |T_1 - P| (5.3),
   its sign from the side of the path P is on (5.4-5.6);
5. gamma_F = e_gamma + arctan(k e_y / v_F), clipped to +-gamma_F,max (2.16);
6. w = f_s k_1 gamma_F (5.7) with f_s the controller server's rate; v_F constant, slowing down
   near the end of the path and while the robot faces away from it.
"""

import math

import numpy as np
import rclpy
from geometry_msgs.msg import PointStamped
from rclpy.node import Node
from robodojo_msgs.srv import ComputeVelocityCommands

K_STANLEY = 1.5  # [1/s] k of eq. 2.16: how hard the lateral error steers
GAMMA_F_MAX_RAD = 1.2  # [rad] gamma_F,max of eq. 2.16 (0 < gamma_F,max < pi/2)
K1_SMOOTHING = 0.3  # [-] k_1 of eq. 5.7: at f_s = 5 Hz, 1.5 rad/s per rad
LOOKAHEAD_M = 0.35  # [m] arc length from T_1 to T_2 (fig. 5.18)
SMOOTHING_WINDOW = 7  # [cells] moving average over the planner's cell centres (0.35 m)
CRUISE_M_S = 0.3  # [m/s] v_F on the open path
MIN_SPEED_M_S = 0.05  # [m/s] v_F close to the goal, so the robot still arrives
SLOW_DOWN_M = 0.6  # [m] start slowing this far from the end of the path
STOP_M = 0.05  # [m] stop this close to the end of the path
V_SOFT_M_S = 0.1  # [m/s] lower bound on v_F inside the arctan of eq. 2.16
SEARCH_AHEAD_M = 1.0  # [m] T_1 is searched only this far past the last one (no shortcuts)


def wrap_angle(angle_rad):
    """The angle in (-pi, pi]."""
    wrapped = math.atan2(math.sin(angle_rad), math.cos(angle_rad))
    return math.pi if wrapped == -math.pi else wrapped


def smooth_path(points, window=SMOOTHING_WINDOW):
    """Moving average of an (n, 2) polyline with its end points kept."""
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


def closest_point(points, x, y, first, last):
    """(index of the segment, point) on the polyline nearest to (x, y), segments first..last."""
    last = min(last, len(points) - 2)
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


def stanley_heading(e_y, e_gamma, v_f):
    """gamma_F of eq. 2.16, clipped to +-gamma_F,max."""
    gamma_f = e_gamma + math.atan(K_STANLEY * e_y / max(v_f, V_SOFT_M_S))
    return min(max(gamma_f, -GAMMA_F_MAX_RAD), GAMMA_F_MAX_RAD)


def forward_speed(distance_to_end_m, e_gamma):
    """v_F [m/s]: cruise, ramping down near the end, scaled by cos(e_gamma) so the robot turns
    on the spot rather than driving away when it faces away from the path."""
    if distance_to_end_m < STOP_M:
        return 0.0
    speed = max(CRUISE_M_S * min(1.0, distance_to_end_m / SLOW_DOWN_M), MIN_SPEED_M_S)
    return speed * max(0.0, math.cos(e_gamma))


class StanleyController(Node):
    def __init__(self):
        super().__init__("stanley_controller")
        # f_s of eq. 5.7: the rate the controller server calls this service at
        self.rate_hz = self.declare_parameter("controller_frequency", 5.0).value
        self.path_key = None
        self.path = self.arc = None
        self.progress = 0
        self.lookahead_pub = self.create_publisher(PointStamped, "lookahead", 10)
        self.service = self.create_service(
            ComputeVelocityCommands, "compute_velocity_commands", self.compute
        )

    def _follow(self, path):
        """A new path (a new goal): smooth it and start from its beginning."""
        stamp = path.header.stamp
        key = (stamp.sec, stamp.nanosec, len(path.poses))
        if key != self.path_key:
            cells = [(p.pose.position.x, p.pose.position.y) for p in path.poses]
            self.path_key = key
            self.path = smooth_path(cells) if len(cells) >= 2 else None
            self.arc = arc_lengths(self.path) if self.path is not None else None
            self.progress = 0

    def compute(self, request, response):
        self._follow(request.path)
        if self.path is None:  # the thesis checks for at least two poses
            self.get_logger().warn("the path has fewer than two poses; standing still")
            return response
        path, arc = self.path, self.arc
        pose = request.pose.pose
        x, y = pose.position.x, pose.position.y
        q = pose.orientation
        yaw = math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))
        window = int(np.searchsorted(arc, arc[self.progress] + SEARCH_AHEAD_M))
        index, t1 = closest_point(path, x, y, self.progress, window)
        self.progress = index
        along_m = arc[index] + math.hypot(*(t1 - path[index]))
        t2 = point_at_arc(path, arc, along_m + LOOKAHEAD_M)
        remaining_m = arc[-1] - along_m
        if math.hypot(t2[0] - t1[0], t2[1] - t1[1]) < 1e-6:  # at the end: aim at the goal
            if math.hypot(path[-1][0] - x, path[-1][1] - y) < STOP_M:
                return response
            t1, t2 = np.array([x, y]), path[-1]
            remaining_m = math.hypot(t2[0] - x, t2[1] - y)
        lookahead = PointStamped()
        lookahead.header = request.path.header
        lookahead.point.x, lookahead.point.y = float(t2[0]), float(t2[1])
        self.lookahead_pub.publish(lookahead)
        e_y, e_gamma = stanley_errors(t1, t2, x, y, yaw)
        v_f = forward_speed(remaining_m, e_gamma)
        gamma_f = stanley_heading(e_y, e_gamma, v_f)
        response.cmd_vel.linear.x = v_f
        response.cmd_vel.angular.z = self.rate_hz * K1_SMOOTHING * gamma_f  # (5.7)
        return response


def main(args=None):
    rclpy.init(args=args)
    node = StanleyController()
    rclpy.spin(node)
    node.destroy_node()
    rclpy.shutdown()


if __name__ == "__main__":
    main()
