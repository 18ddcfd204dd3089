"""The Stanley controller as a service the Nav2 controller server calls (003_4f92d1fa0a49ddae.txt
eq. 2.16 and 5.1-5.7, section 5.9). Starter code of `turtlebot_stanley_ros2`: it answers every
call with straight ahead and never steers.

Every control period (5 Hz, the thesis's rate) the lab's controller server calls
`compute_velocity_commands` (robodojo_msgs/srv/ComputeVelocityCommands) with
- request.pose: geometry_msgs/PoseStamped, the robot's localized pose in the map frame
  (orientation a quaternion: yaw = atan2(2 (w z + x y), 1 - 2 (y^2 + z^2)));
- request.path: nav_msgs/Path, the planner's path to the current goal, a chain of 5 cm grid
  cells: request.path.poses[i].pose.position.x / .y [m];
and publishes the response's cmd_vel (geometry_msgs/Twist: linear.x [m/s], angular.z [rad/s]).
"""

import math

import rclpy
from rclpy.node import Node
from robodojo_msgs.srv import ComputeVelocityCommands

K_STANLEY = 1.0  # [1/s] k of eq. 2.16
GAMMA_F_MAX_RAD = 1.0  # [rad] gamma_F,max of eq. 2.16
K1_SMOOTHING = 0.2  # [-] k_1 of eq. 5.7
SPEED_M_S = 0.2  # [m/s] v_F


class StanleyController(Node):
    def __init__(self):
        super().__init__("stanley_controller")
        # f_s of eq. 5.7: the rate the controller server calls this service at
        self.rate_hz = self.declare_parameter("controller_frequency", 5.0).value
        self.service = self.create_service(
            ComputeVelocityCommands, "compute_velocity_commands", self.compute
        )

    def compute(self, request, response):
        if len(request.path.poses) < 2:  # the thesis checks for at least two poses
            return response
        q = request.pose.pose.orientation
        yaw = math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))  # noqa: F841
        # TODO: T_1 (closest point of the path) and T_2 (a lookahead point further along),
        # e_gamma and e_y (eq. 5.1-5.6), gamma_F (eq. 2.16) and w = f_s k_1 gamma_F (eq. 5.7).
        gamma_f = 0.0
        response.cmd_vel.linear.x = SPEED_M_S
        response.cmd_vel.angular.z = self.rate_hz * K1_SMOOTHING * gamma_f
        return response


def main(args=None):
    rclpy.init(args=args)
    node = StanleyController()
    rclpy.spin(node)
    node.destroy_node()
    rclpy.shutdown()


if __name__ == "__main__":
    main()
