"""Follow the planner's path with the Stanley controller (003_4f92d1fa0a49ddae.txt eq. 2.16 and
5.1-5.7). Starter code of `turtlebot_stanley`: it drives straight ahead and never steers.

obs.plan is a nav_msgs/Path: obs.plan.poses[i].pose.position.x / .y [m], a chain of 5 cm grid
cells from the robot to the current goal. obs.pose is a geometry_msgs/PoseStamped: the robot's
position [m] and orientation (a quaternion; yaw = 2 atan2(q.z, q.w)) in the map frame.
"""

import math

RATE_HZ = 10  # [Hz] f_s
SUBSCRIBE = ["plan", "pose"]

K_STANLEY = 1.0  # [1/s] k of eq. 2.16
GAMMA_F_MAX_RAD = 1.0  # [rad] gamma_F,max of eq. 2.16
K1_SMOOTHING = 0.1  # [-] k_1 of eq. 5.7
SPEED_M_S = 0.2  # [m/s] v_F


def step(obs):
    if obs.plan is None or obs.pose is None:
        return 0.0, 0.0
    q = obs.pose.pose.orientation
    yaw = 2.0 * math.atan2(q.z, q.w)  # noqa: F841 - you will need it
    # TODO: T_1 (closest point of the path) and T_2 (a lookahead point further along),
    # e_gamma and e_y (eq. 5.1-5.6), gamma_F (eq. 2.16) and w = f_s k_1 gamma_F (eq. 5.7).
    gamma_f = 0.0
    return SPEED_M_S, RATE_HZ * K1_SMOOTHING * gamma_f
