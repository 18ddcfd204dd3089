"""Robot state shared by the physics step, the sensors and the drawing code.

Plain dataclasses, no behaviour: the physics step (`server.sim.simulation`) owns and mutates one
`RobotState`; sensors only read it. Units are SI unless a field name says otherwise.

A `Pose2D` is frozen: the physics replaces `state.pose` each tick rather than moving it in place,
so `sim.state.pose.x = 1.0` fails at once instead of teleporting the robot, and a pose someone
kept (a spawn, an odometry origin, a scene) never changes under them.
"""

from __future__ import annotations

from dataclasses import dataclass, field


@dataclass(frozen=True, slots=True)
class Pose2D:
    """A planar pose in the world frame: x, y [m], yaw [rad], counter-clockwise from +x."""

    x: float = 0.0
    y: float = 0.0
    yaw: float = 0.0


@dataclass(slots=True)
class RobotState:
    """Everything about the robot that changes while it moves.

    `pose` is the true pose (ground truth, what the 3D view draws); sensors add their own noise.
    `wheel_left_rad_s`/`wheel_right_rad_s` are the actual wheel speeds after the motor model,
    `linear_m_s`/`angular_rad_s` the body velocities they give. `in_contact` is True while the
    body touches world geometry; `contact_count` counts contacts begun (rising edges; a touch
    within 0.1 s of the last release continues it: simulation.CONTACT_DEBOUNCE_S);
    `contact_angles_rad` are the directions of the touching surfaces seen from the body centre,
    in the robot frame (0 = straight ahead, positive to the left), for bumpers.
    `odometry_pose` integrates the (slipping, miscalibrated) wheel odometry and drifts from `pose`.
    """

    pose: Pose2D = field(default_factory=Pose2D)
    linear_m_s: float = 0.0
    angular_rad_s: float = 0.0
    wheel_left_rad_s: float = 0.0
    wheel_right_rad_s: float = 0.0
    wheel_left_travel_rad: float = 0.0
    wheel_right_travel_rad: float = 0.0
    odometry_pose: Pose2D = field(default_factory=Pose2D)
    in_contact: bool = False
    contact_count: int = 0
    contact_angles_rad: tuple[float, ...] = ()
    distance_travelled_m: float = 0.0
    time_out_of_bounds_s: float = 0.0
    servo_angle_deg: float = 90.0
    servo_target_deg: float = 90.0
    button_pressed: bool = False
    leds_rgb: tuple[int, int, int] = (0, 0, 0)
    buzzer_on: bool = False
    buzzer_until_s: float = 0.0
