"""ImuYaw, Imu, WheelOdometry and Bumper: drift and reset, seeding, frames, bumper mapping."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sandbox.msgs.nav_msgs import Odometry
from sandbox.msgs.sensor_msgs import Imu as ImuMessage
from sandbox.msgs.std_msgs import Float32, Int32MultiArray
from server.sim.sensors.imu import Imu, ImuYaw
from server.sim.sensors.odometry import Bumper, WheelOdometry
from server.sim.state import Pose2D, RobotState
from tests.sim.shapes import make_context, make_world

WORLD = make_world()


def yaw_of(quaternion: object) -> float:
    return 2.0 * math.atan2(quaternion.z, quaternion.w)


def run_yaw(sensor: ImuYaw, seed: int, duration_s: float, period_s: float) -> list[float]:
    """Readings of a robot standing still at yaw 0.3 rad, every `period_s` for `duration_s`."""
    rng = np.random.default_rng(seed)
    state = RobotState(pose=Pose2D(yaw=0.3))
    steps = round(duration_s / period_s)
    return [
        sensor.sample(make_context(WORLD, state, k * period_s), rng).data
        for k in range(1, steps + 1)
    ]


def test_yaw_drifts_with_time_and_reset_clears_it() -> None:
    sensor = ImuYaw()
    readings = run_yaw(sensor, seed=0, duration_s=600.0, period_s=0.05)
    assert sensor.bias_rad != 0.0
    early = np.mean(readings[:200]) - 0.3  # first 10 s
    late = np.mean(readings[-200:]) - 0.3  # last 10 s
    assert abs(late - early) > 0.005  # the heading has wandered
    sensor.reset()
    assert sensor.bias_rad == 0.0
    (reading,) = run_yaw(sensor, seed=1, duration_s=0.05, period_s=0.05)
    assert reading == pytest.approx(0.3, abs=0.03)


def test_drift_spread_matches_the_random_walk_whatever_the_rate() -> None:
    biases = []
    for seed in range(300):
        sensor = ImuYaw()
        run_yaw(sensor, seed=seed, duration_s=600.0, period_s=5.0)  # rate-independent model
        biases.append(sensor.bias_rad)
    expected_sd = 0.002 * math.sqrt(600.0)  # ~0.049 rad after 10 minutes
    assert np.std(biases) == pytest.approx(expected_sd, rel=0.2)


def test_yaw_is_seeded_and_wrapped() -> None:
    first = run_yaw(ImuYaw(), seed=7, duration_s=1.0, period_s=0.05)
    again = run_yaw(ImuYaw(), seed=7, duration_s=1.0, period_s=0.05)
    other = run_yaw(ImuYaw(), seed=8, duration_s=1.0, period_s=0.05)
    assert first == again and first != other
    state = RobotState(pose=Pose2D(yaw=math.pi - 0.001))
    values = [
        ImuYaw(yaw_noise_sd_rad=0.01).sample(make_context(WORLD, state, 0.05), rng).data
        for rng in (np.random.default_rng(s) for s in range(50))
    ]
    assert all(-math.pi < v <= math.pi for v in values)
    assert min(values) < 0.0 < max(values)  # some readings wrapped past +pi
    assert isinstance(ImuYaw().sample(make_context(WORLD), np.random.default_rng(0)), Float32)


def test_imu_message_follows_the_state() -> None:
    sensor = Imu()
    rng = np.random.default_rng(0)
    still = RobotState(pose=Pose2D(yaw=-1.2), linear_m_s=0.0, angular_rad_s=0.4)
    first = sensor.sample(make_context(WORLD, still, 0.05), rng)
    assert isinstance(first, ImuMessage)
    assert yaw_of(first.orientation) == pytest.approx(-1.2, abs=0.03)
    assert first.angular_velocity.z == pytest.approx(0.4, abs=0.03)
    assert first.linear_acceleration.x == pytest.approx(0.0, abs=0.1)  # no previous speed
    assert first.linear_acceleration.z == pytest.approx(9.81, abs=0.1)
    assert len(first.orientation_covariance) == 9 and first.orientation_covariance[8] > 0.0

    moving = RobotState(pose=Pose2D(yaw=-1.2), linear_m_s=0.05, angular_rad_s=0.4)
    second = sensor.sample(make_context(WORLD, moving, 0.10), rng)
    assert second.linear_acceleration.x == pytest.approx(1.0, abs=0.1)  # 0.05 m/s in 0.05 s
    assert second.linear_acceleration.y == pytest.approx(0.05 * 0.4, abs=0.1)
    wire = second.serialize()
    assert ImuMessage.deserialize(wire).serialize() == wire

    sensor.reset()  # forgets the last speed: no spurious acceleration on the next episode
    fast = RobotState(linear_m_s=1.0)
    after = sensor.sample(make_context(WORLD, fast, 0.05), rng)
    assert after.linear_acceleration.x == pytest.approx(0.0, abs=0.1)


def test_imu_drift_resets_and_is_seeded() -> None:
    def last_yaw(sensor: Imu, seed: int) -> float:
        rng = np.random.default_rng(seed)
        message = None
        for k in range(1, 601):
            message = sensor.sample(make_context(WORLD, RobotState(), float(k)), rng)
        return yaw_of(message.orientation)

    sensor = Imu()
    drifted = last_yaw(sensor, seed=3)
    assert sensor.bias_rad != 0.0
    sensor.reset()
    assert sensor.bias_rad == 0.0
    assert last_yaw(sensor, seed=3) == drifted  # same seed after reset: same run
    assert last_yaw(Imu(), seed=4) != drifted


def test_odometry_reports_the_odometry_pose_not_the_true_pose() -> None:
    state = RobotState(
        pose=Pose2D(x=1.0, y=2.0, yaw=0.5),
        odometry_pose=Pose2D(x=1.1, y=1.9, yaw=0.55),
        wheel_left_rad_s=10.0,
        wheel_right_rad_s=10.0,
    )
    odometry = WheelOdometry().sample(make_context(WORLD, state, 2.5), np.random.default_rng(0))
    assert isinstance(odometry, Odometry)
    assert odometry.header.frame_id == "odom" and odometry.child_frame_id == "base_link"
    assert odometry.header.stamp.to_sec() == pytest.approx(2.5)
    position = odometry.pose.pose.position
    assert (position.x, position.y) == (pytest.approx(1.1), pytest.approx(1.9))
    assert yaw_of(odometry.pose.pose.orientation) == pytest.approx(0.55)
    assert odometry.twist.twist.linear.x == pytest.approx(0.036 * 10.0)
    assert odometry.twist.twist.angular.z == pytest.approx(0.0)
    assert len(odometry.pose.covariance) == 36 and odometry.pose.covariance[0] > 0.0
    wire = odometry.serialize()
    assert Odometry.deserialize(wire).serialize() == wire


def test_odometry_twist_turning_on_the_spot() -> None:
    state = RobotState(wheel_left_rad_s=-5.0, wheel_right_rad_s=5.0)
    sensor = WheelOdometry(wheel_radius_m=0.03, track_m=0.2)
    twist = sensor.sample(make_context(WORLD, state), np.random.default_rng(0)).twist.twist
    assert twist.linear.x == pytest.approx(0.0)
    assert twist.angular.z == pytest.approx(2 * 0.03 * 5.0 / 0.2)


@pytest.mark.parametrize(
    ("angles_deg", "expected"),
    [
        ((), (0, 0)),
        ((0.0,), (1, 1)),
        ((8.0,), (1, 1)),
        ((-8.0,), (1, 1)),
        ((30.0,), (1, 0)),
        ((90.0,), (1, 0)),
        ((-30.0,), (0, 1)),
        ((-90.0,), (0, 1)),
        ((30.0, -60.0), (1, 1)),
        ((120.0,), (0, 0)),
        ((180.0,), (0, 0)),
        ((-135.0,), (0, 0)),
        ((390.0,), (1, 0)),  # unwrapped angles are wrapped first
    ],
)
def test_bumper_left_right_mapping(
    angles_deg: tuple[float, ...], expected: tuple[int, int]
) -> None:
    state = RobotState(contact_angles_rad=tuple(math.radians(a) for a in angles_deg))
    message = Bumper().sample(make_context(WORLD, state), np.random.default_rng(0))
    assert isinstance(message, Int32MultiArray)
    assert list(message.data) == list(expected)
