"""The fold from messages (as telemetry decodes them) to what the view shows."""

from __future__ import annotations

import math

import pytest

from sandbox.msgs.geometry_msgs import Point, Pose, PoseStamped, Quaternion
from sandbox.msgs.nav_msgs import Path
from server.runs.tf import tf_message
from server.service.decode import decode
from server.viz.view_state import TRAIL_STEP_M, ViewState, frame_from_transform

NS = 1_000_000_000


def tf(x: float, y: float, yaw: float, frames=None) -> dict:
    message = tf_message(0, x, y, yaw, frames or {}, odom_origin=(0.0, 0.0, 0.0))
    return decode(message._type, message.serialize())


def test_tf_gives_the_pose_and_the_sensor_frames():
    state = ViewState()
    frames = {"ir_link": (0.045, 0.0, 0.5), "laser": (0.0, 0.0, math.pi, math.pi)}
    state.apply("tf", "tf2_msgs/TFMessage", 1.0, tf(1.0, 2.0, 0.3, frames))
    assert state.pose == pytest.approx((1.0, 2.0, 0.3))
    ir, laser = state.sensor_frames["ir_link"], state.sensor_frames["laser"]
    assert (ir.x, ir.heading, ir.sign) == pytest.approx((0.045, 0.5, 1.0))
    # The upside-down lidar: lidar angle a points at robot direction pi - a (its 0 is the rear).
    assert laser.sign == -1.0 and laser.direction(0.0) == pytest.approx(math.pi)
    assert math.cos(laser.direction(math.pi / 2)) == pytest.approx(0.0, abs=1e-12)
    assert math.sin(laser.direction(math.pi / 2)) == pytest.approx(1.0)  # left is (0, pi)
    assert "odom" not in state.sensor_frames  # a child of map, not of the robot


def test_the_trail_grows_a_point_per_step_moved():
    state = ViewState()
    for i in range(100):
        state.apply("tf", "tf2_msgs/TFMessage", i / 30, tf(i * 0.001, 0.0, 0.0))
    assert len(state.trail) == pytest.approx(0.099 / TRAIL_STEP_M + 1, abs=1)
    assert state.trail[0] == (0.0, 0.0)


def test_leds_buzzer_and_bad_values():
    state = ViewState()
    state.apply("Leds", "std_msgs/Int32MultiArray", 0.5, {"layout": {}, "data": [255, 0, 10]})
    assert state.leds_rgb == (255, 0, 10)
    state.apply("Leds", "std_msgs/Int32MultiArray", 0.6, {"layout": {}, "data": [300, 0, 0]})
    assert state.leds_rgb == (255, 0, 10)  # the robot refused it; so does the view
    state.apply("Buzzer", "std_msgs/Bool", 1.0, {"data": True})
    assert state.buzzer_on
    state.time_s = 2.05
    assert not state.buzzer_on  # one second of tone
    state.apply("Buzzer", "std_msgs/Bool", 2.1, {"data": True})
    state.apply("Buzzer", "std_msgs/Bool", 2.2, {"data": False})
    assert not state.buzzer_on


def test_plan_goal_and_a_published_lookahead():
    state = ViewState()
    path = Path(poses=[PoseStamped(pose=Pose(position=Point(x=i * 0.1, y=1.0))) for i in range(5)])
    state.apply("plan", path._type, 1.0, decode(path._type, path.serialize()))
    # Point by point: pytest 9.2's approx() refuses nested sequences (a list of tuples).
    assert len(state.plan) == 5
    for point, expected in zip(state.plan, [(i * 0.1, 1.0) for i in range(5)], strict=True):
        assert point == pytest.approx(expected)
    turned = Quaternion(z=1.0, w=0.0)  # half a turn
    goal = PoseStamped(pose=Pose(position=Point(x=3.0, y=4.0), orientation=turned))
    state.apply("goal_pose", goal._type, 1.0, decode(goal._type, goal.serialize()))
    assert state.goal == pytest.approx((3.0, 4.0, math.pi))
    state.apply("pose", goal._type, 1.0, decode(goal._type, goal.serialize()))
    assert "pose" in state.latest  # localization's pose is not a goal
    state.apply("lookahead", goal._type, 1.0, decode(goal._type, goal.serialize()))
    assert state.lookahead == (3.0, 4.0)


def test_malformed_messages_are_ignored():
    state = ViewState()
    state.apply("tf", "tf2_msgs/TFMessage", 1.0, {"transforms": [{"header": {}}]})
    state.apply("plan", "nav_msgs/Path", 1.0, {"poses": [{"pose": None}]})
    state.apply("x", "std_msgs/Int32", 1.0, None)
    assert state.pose is None and state.plan is None


def test_frame_from_transform_reads_a_plain_yaw():
    frame = frame_from_transform(
        {"translation": {"x": 1, "y": 2}, "rotation": {"x": 0, "y": 0, "z": 1, "w": 0}}
    )
    assert (frame.x, frame.y, frame.heading, frame.sign) == pytest.approx((1, 2, math.pi, 1))
