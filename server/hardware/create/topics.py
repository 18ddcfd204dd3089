"""From Open Interface stream frames to the simulated turtlebot's topics: `odom`
(nav_msgs/Odometry) and `bumper` (std_msgs/Int32MultiArray [left, right], 1 = pressed), as
server/sim/robots/turtlebot.py and server/sim/sensors/odometry.py publish them.

Pure: the caller passes the frames and the times; no port, no thread, no clock.

- odom: pose from the wheel encoders (kinematics.EncoderOdometry); twist = the motion since the
  previous odom message over its duration. That duration counts 15 ms per frame (the robot's
  own clock) rather than the host's receive times, which bunch frames up: a USB-serial adapter
  holds bytes for its latency timer and a busy host reads late, and at 20 Hz a frame more or
  less in a window is +-30% speed. When frames went missing (the host's time is longer than
  the frames account for by 3 periods) the host's time is used.
- Rate: `publish_rate_hz` on average, on a fixed schedule met by the next frame.
- bumper: packet 7's bump bits, published with each odom message and at once when a switch
  changes (a bump should not wait up to 50 ms).
"""

from __future__ import annotations

from collections.abc import Iterable

from sandbox.msgs import Message, Time, get_message_class
from server.hardware.create import kinematics, oi
from server.sim.geometry import yaw_quaternion

TOPIC_CMD_VEL = "cmd_vel"
TOPIC_ODOM = "odom"
TOPIC_BUMPER = "bumper"
PUBLISH_RATE_HZ = 20.0  # [Hz] the simulated turtlebot's odom and bumper rate
_LOST_FRAMES_SLACK = 3  # [frames] host time this much past the frames' time: frames were lost
# Odometry variances as the simulated base reports them (server/sim/sensors/odometry.py):
# pose (x, y, z, roll, pitch, yaw) [m^2, rad^2], twist [(m/s)^2, (rad/s)^2]; 1e6 = unobservable.
POSE_VARIANCES = (1e-3, 1e-3, 1e6, 1e6, 1e6, 1e-2)
TWIST_VARIANCES = (1e-4, 1e-6, 1e6, 1e6, 1e6, 1e-3)


def _diagonal(variances: tuple[float, ...]) -> list[float]:
    """A row-major n x n covariance with `variances` on the diagonal."""
    size = len(variances)
    flat = [0.0] * (size * size)
    for index, variance in enumerate(variances):
        flat[index * size + index] = float(variance)
    return flat


class CreateTopics:
    """Keeps the odometry and bumper state of one robot and says what to publish when."""

    def __init__(
        self,
        *,
        publish_rate_hz: float = PUBLISH_RATE_HZ,
        frame_id: str = "odom",
        child_frame_id: str = "base_link",
    ) -> None:
        if not publish_rate_hz > 0.0:
            raise ValueError(f"publish_rate_hz must be > 0, got {publish_rate_hz}")
        self.publish_period_s = 1.0 / publish_rate_hz
        self.frame_id = frame_id
        self.child_frame_id = child_frame_id
        self.odometry = kinematics.EncoderOdometry()
        self.bumper: tuple[int, int] | None = None  # (left, right), None before the first frame
        self.wheel_dropped = False
        self._odometry_cls = get_message_class("nav_msgs/Odometry")
        self._bumper_cls = get_message_class("std_msgs/Int32MultiArray")
        # Motion since the last odom message, for its twist.
        self._window_distance_m = 0.0
        self._window_yaw_rad = 0.0
        self._window_frames = 0
        self._window_start_s: float | None = None
        self._next_publish_s: float | None = None  # on a fixed schedule: 20 Hz on average

    def on_frames(
        self, frames: Iterable[dict[int, int]], now_s: float, stamp_s: float
    ) -> list[tuple[str, Message]]:
        """Take frames carrying packets 7, 43 and 44, received at `now_s` (a monotonic time
        [s]); return the (topic, message) pairs due, stamped `stamp_s` [s]."""
        bumper_changed = False
        for packets in frames:
            step = self.odometry.update(
                packets[oi.LEFT_ENCODER_COUNTS], packets[oi.RIGHT_ENCODER_COUNTS]
            )
            self._window_distance_m += step.distance_m
            self._window_yaw_rad += step.yaw_change_rad
            self._window_frames += 1
            bits = packets[oi.BUMPS_WHEEL_DROPS]
            bumper = (int(bool(bits & oi.BUMP_LEFT_BIT)), int(bool(bits & oi.BUMP_RIGHT_BIT)))
            bumper_changed |= bumper != self.bumper
            self.bumper = bumper
            self.wheel_dropped = bool(bits & (oi.WHEEL_DROP_LEFT_BIT | oi.WHEEL_DROP_RIGHT_BIT))
        if self._window_start_s is None:
            self._window_start_s = now_s
        out: list[tuple[str, Message]] = []
        due = self._next_publish_s is None or now_s >= self._next_publish_s
        if due:
            out.append((TOPIC_ODOM, self._odometry_message(now_s, stamp_s)))
            # Keep the schedule (frames come every 15 ms, so "50 ms since the last" would give
            # 60 ms gaps, 16.7 Hz); after a stall, start it again from now.
            if self._next_publish_s is None or now_s - self._next_publish_s > self.publish_period_s:
                self._next_publish_s = now_s
            self._next_publish_s += self.publish_period_s
        if self.bumper is not None and (due or bumper_changed):
            out.append((TOPIC_BUMPER, self._bumper_cls(data=list(self.bumper))))
        return out

    def _window_duration_s(self, now_s: float) -> float:
        start_s = self._window_start_s if self._window_start_s is not None else now_s
        host_s = now_s - start_s
        robot_s = self._window_frames * oi.STREAM_PERIOD_S
        lost = host_s > robot_s + _LOST_FRAMES_SLACK * oi.STREAM_PERIOD_S
        return host_s if lost else robot_s

    def _odometry_message(self, now_s: float, stamp_s: float) -> Message:
        window_s = self._window_duration_s(now_s)
        linear_m_s = self._window_distance_m / window_s if window_s > 0 else 0.0
        angular_rad_s = self._window_yaw_rad / window_s if window_s > 0 else 0.0
        self._window_distance_m = self._window_yaw_rad = 0.0
        self._window_frames = 0
        self._window_start_s = now_s
        pose = self.odometry.pose
        message = self._odometry_cls()
        message.header.stamp = Time.from_sec(stamp_s)
        message.header.frame_id = self.frame_id
        message.child_frame_id = self.child_frame_id
        message.pose.pose.position.x = pose.x_m
        message.pose.pose.position.y = pose.y_m
        orientation = message.pose.pose.orientation
        _, _, orientation.z, orientation.w = yaw_quaternion(pose.yaw_rad)
        message.pose.covariance = _diagonal(POSE_VARIANCES)
        message.twist.twist.linear.x = linear_m_s
        message.twist.twist.angular.z = angular_rad_s
        message.twist.covariance = _diagonal(TWIST_VARIANCES)
        return message
