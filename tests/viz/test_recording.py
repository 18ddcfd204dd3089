"""Replay reads real recordings (made by real sandboxed runs) back into the view's state."""

from __future__ import annotations

import pytest

from server.runs.recorder import RECORDING_FILE
from server.sim.registry import get_robot
from server.sim.world import load_world
from server.viz.rays import sensor_drawings
from server.viz.recording import RecordingError, load_recording


def test_a_crowbot_recording_replays_pose_leds_and_buzzer(crowbot_run):
    recording = load_recording(crowbot_run / RECORDING_FILE)
    assert recording.metadata["robot"] == "crowbot"
    assert recording.metadata["world"] == "light_arena"
    assert recording.duration_s == pytest.approx(2.0, abs=0.05)
    early, late = recording.state_at(0.3), recording.state_at(1.5)
    assert early.leds_rgb is None and late.leds_rgb == (255, 0, 0)
    assert not early.buzzer_on and late.buzzer_on  # sounded at 1.0 s, for a second
    assert not recording.state_at(2.15).buzzer_on  # and quiet a second after
    assert early.pose != late.pose  # it turned and rolled
    assert len(early.trail) < len(late.trail) == len(recording.state_at(1.5).trail)
    assert recording.state_at(-1.0).pose is None  # before the first message: nothing


def test_a_turtlebot_recording_replays_plan_goal_and_sensors(turtlebot_run):
    recording = load_recording(turtlebot_run / RECORDING_FILE)
    state = recording.state_at(recording.duration_s)
    assert state.plan and state.goal == pytest.approx((6.0, 1.4, 0.0), abs=1e-9)
    assert state.plan[-1] == pytest.approx((6.0, 1.4), abs=0.05)
    assert "ultrasonic_0" in state.sensor_frames and "camera_depth_frame" in state.sensor_frames
    robot = get_robot("turtlebot")
    drawings = sensor_drawings(state, robot, robot.build_sensors(), load_world("office"))
    assert len(drawings["scan"].points) > 10  # the depth slice sees the lab's walls
    assert {f"ultrasonic/range_{i}" for i in range(7)} <= drawings.keys()
    assert "map" in recording.topics  # recorded, though the view draws the world's own map


def test_a_missing_or_broken_recording_is_a_sentence(tmp_path):
    with pytest.raises(RecordingError, match="no recording"):
        load_recording(tmp_path / RECORDING_FILE)
    (tmp_path / RECORDING_FILE).write_bytes(b"not an mcap file")
    with pytest.raises(RecordingError, match="cannot read the recording"):
        load_recording(tmp_path / RECORDING_FILE)
