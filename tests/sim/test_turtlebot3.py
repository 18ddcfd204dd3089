"""The TurtleBot3 Burger: the LDS-01 scan as the real driver lays it out, the firmware's velocity
clamp, wheel units and watchdog, odometry and IMU following the motion, the off-centre body, and
the worlds it is placed in."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from sandbox.msgs.geometry_msgs import Twist, Vector3
from server.sim.checks import robot_problems
from server.sim.motors import TB3_UNITS_PER_RAD_S, dynamixel_units
from server.sim.registry import get_robot, robots_for_world
from server.sim.robots.turtlebot3 import MAX_ANGULAR_RAD_S, MAX_LINEAR_M_S
from server.sim.sensors.lds01 import (
    NEAR_PRECISION_M,
    RANGE_MAX_M,
    Lds01,
    accuracy_band_m,
)
from server.sim.simulation import Simulation
from server.sim.state import Pose2D, RobotState
from server.sim.world import World, load_world
from tests.sim.shapes import make_context, make_world

SCAN_X_M = -0.032  # [m] base_scan behind base_link (URDF scan_joint)


def twist(linear: float = 0.0, angular: float = 0.0) -> Twist:
    return Twist(linear=Vector3(x=linear), angular=Vector3(z=angular))


def scan_of(world: World, pose: Pose2D | None = None, seed: int = 0):
    state = RobotState(pose=pose if pose is not None else Pose2D())
    return Lds01().sample(make_context(world, state), np.random.default_rng(seed))


def tb3_world(**shapes) -> World:
    return dataclasses.replace(make_world(**shapes), robots=("turtlebot3",))


# ------------------------------------------------------------------------------- scan layout
def test_scan_fields_are_the_drivers() -> None:
    scan = scan_of(make_world())
    assert len(scan.ranges) == len(scan.intensities) == 360
    assert scan.header.frame_id == "base_scan"
    assert scan.angle_min == 0.0
    assert scan.angle_increment == pytest.approx(math.radians(1.0))
    assert scan.angle_max == pytest.approx(2 * math.pi - math.radians(1.0))
    assert (scan.range_min, scan.range_max) == (0.12, 3.5)
    assert scan.scan_time == pytest.approx(0.2)  # 300 rpm
    assert scan.time_increment == pytest.approx(0.2 / 360)


@pytest.mark.parametrize("yaw", [0.0, 2.3])
def test_a_wall_ahead_is_at_index_0_and_one_on_the_left_at_index_90(yaw: float) -> None:
    pose = Pose2D(x=0.4, y=-0.7, yaw=yaw)
    c, s = math.cos(yaw), math.sin(yaw)
    scanner = (pose.x + c * SCAN_X_M, pose.y + s * SCAN_X_M)

    def wall(forward_m: float, left_m: float, along: tuple[float, float]):
        # A 4 m wall through the robot-frame point (forward, left) from the scanner.
        px = scanner[0] + c * forward_m - s * left_m
        py = scanner[1] + s * forward_m + c * left_m
        dx, dy = c * along[0] - s * along[1], s * along[0] + c * along[1]
        return (px - 2 * dx, py - 2 * dy, px + 2 * dx, py + 2 * dy)

    ahead = np.asarray(scan_of(make_world(segments=[wall(1.0, 0.0, (0, 1))]), pose).ranges)
    assert ahead[0] == pytest.approx(1.0, abs=0.05)
    assert ahead[[90, 180, 270]].tolist() == [0.0, 0.0, 0.0]  # nothing else there
    assert np.count_nonzero(ahead) < 180  # only the front half sees the wall
    left = np.asarray(scan_of(make_world(segments=[wall(0.0, 1.0, (1, 0))]), pose).ranges)
    assert left[90] == pytest.approx(1.0, abs=0.05)
    assert left[270] == 0.0 and left[0] == 0.0
    # Counter-clockwise: the wall on the left shows between index 1 and 179, never right.
    assert np.all(left[181:] == 0.0) and np.count_nonzero(left[1:180]) > 100


def test_beyond_3_5_m_and_below_the_scan_plane_give_the_no_return_value() -> None:
    far = scan_of(make_world(segments=[(3.8, -5.0, 3.8, 5.0)]))
    assert far.ranges[0] == 0.0  # the driver's value for no echo: 0.0, not inf or range_max
    low = scan_of(make_world(segments=[(1.0, -5.0, 1.0, 5.0)], segment_height=0.15))
    assert np.all(np.asarray(low.ranges) == 0.0)  # 0.15 m is under the 0.182 m scan plane
    assert np.all(np.asarray(low.intensities) == 0.0)
    close = scan_of(make_world(circles=[(0.05, 0.0, 0.02)]))
    assert close.ranges[0] == 0.0  # 6 cm from the scanner: below range_min


def test_noise_stays_in_the_datasheet_band_and_has_the_precision_spread() -> None:
    sensor = Lds01()
    rng = np.random.default_rng(5)
    for true_m in (0.2, 0.45, 0.5, 1.0, 2.0, 3.3):
        readings = sensor.ranges(np.full(20_000, true_m), rng).astype(np.float64)
        error = readings - true_m
        band = float(accuracy_band_m(np.array([true_m]))[0])
        assert np.all(np.abs(error) <= band + 0.0005 + 1e-6), true_m  # + half a mm rounding
        assert np.allclose(readings * 1000, np.round(readings * 1000), atol=1e-3)  # whole mm
        # Half the datasheet precision as the standard deviation (+-10 mm, +-3.5 %).
        expected_sd = 0.5 * (NEAR_PRECISION_M if true_m < 0.5 else 0.035 * true_m)
        assert np.std(error) == pytest.approx(expected_sd, rel=0.15), true_m
        assert abs(np.mean(error)) < expected_sd / 10


def test_scans_are_seeded() -> None:
    world = make_world(segments=[(1.0, -5.0, 1.0, 5.0)])
    assert scan_of(world, seed=3).ranges.tolist() == scan_of(world, seed=3).ranges.tolist()
    assert scan_of(world, seed=3).ranges.tolist() != scan_of(world, seed=4).ranges.tolist()


def test_a_wall_just_inside_range_max_is_still_seen() -> None:
    world = make_world(segments=[(3.4 - SCAN_X_M, -5.0, 3.4 - SCAN_X_M, 5.0)])
    ranges = np.asarray(scan_of(world).ranges)
    assert 3.2 < ranges[0] <= RANGE_MAX_M


# ------------------------------------------------------------------------------- motors
def test_velocity_commands_are_clamped_as_the_firmware_does() -> None:
    assert round(MAX_LINEAR_M_S, 4) == 0.2108  # 0.033 m * 2 pi * 61 rpm / 60
    assert round(MAX_ANGULAR_RAD_S, 3) == 2.635  # / the 0.080 m turning radius
    sim = Simulation("turtlebot3", tb3_world())
    for _ in range(40):  # keep commanding: the watchdog stops stale commands
        sim.apply("cmd_vel", twist(5.0))
        sim.step(0.05)
    # 0.2108 m/s asked of the wheels; the Dynamixel limit of 265 units (60.7 rpm) caps it.
    assert sim.state.linear_m_s == pytest.approx(265 / TB3_UNITS_PER_RAD_S * 0.033, abs=1e-3)
    sim.reset()
    for _ in range(40):
        sim.apply("cmd_vel", twist(0.0, -10.0))
        sim.step(0.05)
    assert sim.state.angular_rad_s == pytest.approx(-MAX_ANGULAR_RAD_S, rel=0.02)
    assert sim.state.linear_m_s == pytest.approx(0.0, abs=1e-6)


def test_wheel_goals_are_whole_dynamixel_units() -> None:
    assert dynamixel_units(0.1 / 0.033) == 126  # 126.36 truncated
    assert dynamixel_units(-0.1 / 0.033) == -126  # toward zero, as a C cast
    assert dynamixel_units(100.0) == 265 and dynamixel_units(-100.0) == -265
    sim = Simulation("turtlebot3", tb3_world())
    for _ in range(40):
        sim.apply("cmd_vel", twist(0.1))
        sim.step(0.05)
    assert sim.state.linear_m_s == pytest.approx(126 / TB3_UNITS_PER_RAD_S * 0.033, abs=1e-5)
    assert sim.state.linear_m_s < 0.1


def test_the_watchdog_stops_the_wheels_half_a_second_after_the_last_command() -> None:
    sim = Simulation("turtlebot3", tb3_world())
    sim.apply("cmd_vel", twist(0.15))
    sim.step(0.45)
    assert sim.state.linear_m_s > 0.14  # still obeying
    sim.step(0.6)
    assert sim.state.linear_m_s < 0.01  # 0.5 s without a command: the firmware wrote zero
    travelled = sim.state.pose.x
    sim.step(2.0)
    assert sim.state.pose.x == pytest.approx(travelled, abs=1e-3)


def test_an_unrefreshed_robot_never_moves_before_its_first_command() -> None:
    sim = Simulation("turtlebot3", tb3_world())
    sim.step(1.0)
    assert (sim.state.pose.x, sim.state.pose.y) == (0.0, 0.0)


# ------------------------------------------------------------------------------- odom, imu
def test_odometry_and_imu_follow_the_motion() -> None:
    sim = Simulation("turtlebot3", tb3_world(), seed=2, spawn=Pose2D(1.0, 2.0, 1.0))
    start = sim.read("imu")
    assert start.header.frame_id == "imu_link"
    assert 2 * math.atan2(start.orientation.z, start.orientation.w) == pytest.approx(0, abs=0.02)
    for _ in range(60):  # 3 s ahead, then 2 s turning left
        sim.apply("cmd_vel", twist(0.2))
        sim.step(0.05)
    for _ in range(40):
        sim.apply("cmd_vel", twist(0.0, 1.0))
        sim.step(0.05)
    odom = sim.read("odom")
    assert (odom.header.frame_id, odom.child_frame_id) == ("odom", "base_footprint")
    assert odom.twist.twist.angular.z == pytest.approx(1.0, rel=0.05)
    travelled_m = math.hypot(sim.state.pose.x - 1.0, sim.state.pose.y - 2.0)
    assert odom.pose.pose.position.x == pytest.approx(travelled_m, rel=0.05)
    assert abs(odom.pose.pose.position.y) < 0.1 * travelled_m  # drifts, but little
    turned = sim.state.pose.yaw - 1.0
    odom_yaw = 2 * math.atan2(odom.pose.pose.orientation.z, odom.pose.pose.orientation.w)
    assert odom_yaw == pytest.approx(turned, abs=0.15)
    imu = sim.read("imu")
    imu_yaw = 2 * math.atan2(imu.orientation.z, imu.orientation.w)
    assert imu_yaw == pytest.approx(turned, abs=0.05)  # from start-up, not the world's east
    assert imu.angular_velocity.z == pytest.approx(1.0, abs=0.1)
    assert imu.orientation_covariance[0] == 0.0025 and imu.linear_acceleration_covariance[8] == 0.04
    assert list(odom.pose.covariance) == [0.0] * 36  # the firmware leaves them unset


def test_rates_are_the_firmwares() -> None:
    sim = Simulation("turtlebot3", tb3_world())
    counts: dict[str, int] = {}
    for published in sim.step(1.0):
        counts[published.topic] = counts.get(published.topic, 0) + 1
    assert counts == {"scan": 5, "odom": 30, "imu": 200}


# ------------------------------------------------------------------------------- body, worlds
def test_the_body_is_behind_the_axle_so_the_nose_gets_close_to_a_wall() -> None:
    sim = Simulation("turtlebot3", tb3_world(segments=[(0.5, -2.0, 0.5, 2.0)]))
    for _ in range(60):
        sim.apply("cmd_vel", twist(0.2))
        sim.step(0.05)
    assert sim.state.in_contact
    # Body centre 32 mm behind the axle, radius 0.113 m: the axle stops 0.081 m from the wall.
    assert sim.state.pose.x == pytest.approx(0.5 - 0.113 + 0.032, abs=0.002)


def test_the_registry_entry_is_valid_and_the_worlds_take_it() -> None:
    robot = get_robot("turtlebot3")
    assert robot_problems(robot) == []
    assert set(robots_for_world("turtlebot3")) == {
        "crop_rows",
        "obstacle_maze",
        "office",
        "wall_approach",
    }
    assert {t.name for t in robot.topics()} == {"scan", "odom", "imu", "cmd_vel"}
    assert set(robot.frames) == {"base_footprint", "base_scan", "imu_link"}


def test_a_body_offset_outside_the_body_is_refused() -> None:
    robot = get_robot("turtlebot3")
    broken = dataclasses.replace(robot.geometry, body_offset_x_m=0.2)
    robot.geometry = broken  # on this instance only
    assert any("body_offset_x_m" in problem for problem in robot_problems(robot))
    assert robot_problems(get_robot("turtlebot3")) == []


@pytest.mark.parametrize("world_id", robots_for_world("turtlebot3"))
def test_every_spawn_leaves_the_burger_free(world_id: str) -> None:
    world = load_world(world_id)
    geometry = get_robot("turtlebot3").geometry
    for spawn in world.spawns:
        centre_x = spawn.x + geometry.body_offset_x_m * math.cos(spawn.yaw)
        centre_y = spawn.y + geometry.body_offset_x_m * math.sin(spawn.yaw)
        assert world.clearance(centre_x, centre_y) > geometry.body_radius_m + 0.05, spawn.name
        sim = Simulation("turtlebot3", world_id, spawn=spawn.name)
        sim.step(0.2)
        assert not sim.state.in_contact, spawn.name
