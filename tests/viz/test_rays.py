"""Sensor readings as world geometry: scans, cones, the CrowBot's frameless Distance."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sandbox.msgs.sensor_msgs import LaserScan, Range
from sandbox.msgs.std_msgs import Header, Int32
from server.service.decode import decode
from server.sim.registry import get_robot
from server.sim.robots.crowbot import ULTRASONIC_MOUNT
from server.sim.sensors.ultrasonic import CONE_FULL_ANGLE_RAD
from server.sim.world import load_world
from server.viz.rays import range_cone, scan_points, sensor_drawings, static_frame
from server.viz.view_state import SensorFrame, ViewState


def decoded(message) -> dict:
    return decode(message._type, message.serialize())


def test_a_scan_becomes_its_valid_hit_points():
    scan = LaserScan(
        header=Header(frame_id="laser"),
        angle_min=0.0,
        angle_increment=math.pi / 2,
        range_min=0.12,
        range_max=8.0,
        ranges=[1.0, 0.0, 2.0, float("nan")],  # 0.0: the YDLidar's "no return"
    )
    lidar = static_frame((0.0, 0.0, math.pi, math.pi))  # upside down: direction = pi - angle
    points = scan_points((1.0, 1.0, 0.0), lidar, decoded(scan))
    # Angle 0 is the rear (-x), angle pi the front (+x).
    assert points == pytest.approx(np.array([[0.0, 1.0], [3.0, 1.0]]), abs=1e-6)  # float32


def test_a_range_is_a_cone_as_long_as_its_reading():
    reading = Range(
        header=Header(frame_id="ultrasonic_0"),
        field_of_view=0.26,
        min_range=0.02,
        max_range=4.0,
        range=1.5,
    )
    frame = SensorFrame(0.1, 0.0, -math.pi / 2, 1.0)  # on the right side, looking right
    cone = range_cone((0.0, 0.0, math.pi / 2), frame, decoded(reading))  # robot faces +y
    assert cone[:, :2] == pytest.approx(np.tile([0.0, 0.1], (3, 1)), abs=1e-9)
    ends = cone[:, 2:] - cone[:, :2]
    assert np.hypot(ends[:, 0], ends[:, 1]) == pytest.approx([1.5] * 3)
    assert ends[1] == pytest.approx([1.5, 0.0], abs=1e-9)  # the axis points along +x
    reading.range = float("inf")
    far = range_cone((0.0, 0.0, 0.0), frame, decoded(reading))
    assert np.hypot(*(far[1, 2:] - far[1, :2])) == pytest.approx(4.0)


def test_the_crowbots_distance_is_drawn_by_its_own_sensor_in_the_robot_frame():
    robot, world = get_robot("crowbot"), load_world("light_arena")
    state = ViewState(pose=(1.0, 1.0, 2.0))  # the pose does not matter: robot frame
    state.latest["Distance"] = ("std_msgs/Int32", decoded(Int32(data=50)))
    drawings = sensor_drawings(state, robot, robot.build_sensors(), world)
    segments = drawings["Distance"].segments
    assert len(segments) == 3
    assert segments[1] == pytest.approx([ULTRASONIC_MOUNT.x_m, 0.0, 0.55, 0.0])
    half = CONE_FULL_ANGLE_RAD / 2
    dx, dy = segments[2, 2:] - segments[2, :2]
    assert math.atan2(dy, dx) == pytest.approx(half)  # the cone's left edge


def test_bad_readings_are_left_out_and_only_the_topics_asked_for_are_drawn():
    robot, world = get_robot("turtlebot"), load_world("office")
    state = ViewState()
    state.latest["scan"] = ("sensor_msgs/LaserScan", {"header": {"frame_id": "camera_depth_frame"}})
    assert sensor_drawings(state, robot, robot.build_sensors(), world) == {}  # no ranges
    reading = Range(header=Header(frame_id="ultrasonic_3"), field_of_view=0.26, max_range=4.0)
    state.latest["ultrasonic/range_3"] = ("sensor_msgs/Range", decoded(reading))
    sensors = robot.build_sensors()
    assert set(sensor_drawings(state, robot, sensors, world)) == {"ultrasonic/range_3"}
    assert sensor_drawings(state, robot, sensors, world, topics={"scan"}) == {}
