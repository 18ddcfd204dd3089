"""Where a sensor sits on the robot: an offset in the robot frame (x forward, y left [m]) and a
heading relative to the robot's nose [rad, counter-clockwise]."""

from __future__ import annotations

import math
from dataclasses import dataclass

from server.sim.state import Pose2D


@dataclass(frozen=True, slots=True)
class Mount:
    x_m: float = 0.0
    y_m: float = 0.0
    yaw_rad: float = 0.0

    def in_world(self, robot: Pose2D, extra_yaw_rad: float = 0.0) -> tuple[float, float, float]:
        """World-frame (x [m], y [m], heading [rad]) of the sensor on a robot at `robot`;
        `extra_yaw_rad` turns it further (a servo)."""
        cos_yaw, sin_yaw = math.cos(robot.yaw), math.sin(robot.yaw)
        return (
            robot.x + cos_yaw * self.x_m - sin_yaw * self.y_m,
            robot.y + sin_yaw * self.x_m + cos_yaw * self.y_m,
            robot.yaw + self.yaw_rad + extra_yaw_rad,
        )
