"""A run's whole view on a real viser server: the robot drawn from a state, the controls wired
(a click on a mapped floor sets the goal, a dragged light moves), replay and live following."""

from __future__ import annotations

import asyncio
import math
import threading
import time
from types import SimpleNamespace

import pytest

from sandbox.protocol import Clock
from server.runs.commands import Goal, Light, RunCommand
from server.runs.recorder import RECORDING_FILE
from server.runs.run import Run
from server.service.telemetry import RunTelemetry
from server.viz.live import follow_live
from server.viz.recording import load_recording
from server.viz.replay import ReplayPlayer
from server.viz.view import SceneView, floor_point
from server.viz.view_state import SensorFrame, ViewState
from tests.viz.conftest import crowbot_spec


class SentCommands:
    """The view's `send`: keeps the typed commands it is given, as RunService.command would
    take them."""

    def __init__(self) -> None:
        self.sent: list[RunCommand] = []

    def __call__(self, command: RunCommand) -> bool:
        self.sent.append(command)
        return True

    @property
    def goals(self) -> list[tuple[float, float, float]]:
        return [(c.x, c.y, c.yaw) for c in self.sent if isinstance(c, Goal)]

    @property
    def lights(self) -> list[tuple[str | None, float, float]]:
        return [(c.name, c.x, c.y) for c in self.sent if isinstance(c, Light)]


def wait_until(predicate, timeout_s: float = 5.0) -> None:
    deadline = time.monotonic() + timeout_s
    while not predicate():
        assert time.monotonic() < deadline, "timed out"
        time.sleep(0.01)


def test_the_robot_follows_the_state(viser_server):
    view = SceneView(viser_server, "ir_scout", "light_arena")
    scene = viser_server.scene
    state = ViewState(pose=(0.5, 0.7, math.pi / 2), time_s=1.0)
    state.sensor_frames["ir_link"] = SensorFrame(0.045, 0.0, 0.3, 1.0)
    view.draw(state)
    robot = scene.get_handle_by_name("/robot")
    assert tuple(robot.position) == pytest.approx((0.5, 0.7, 0.0))
    assert tuple(robot.wxyz) == pytest.approx((math.sqrt(0.5), 0, 0, math.sqrt(0.5)))
    block = scene.get_handle_by_name("/robot/sensors/ir_link")
    assert tuple(block.position[:2]) == pytest.approx((0.045, 0.0))
    assert scene.get_handle_by_name("/robot/led_0") is None  # the IR scout has no LEDs


def test_the_turtlebots_ring_and_depth_camera_are_drawn_from_the_start(viser_server):
    SceneView(viser_server, "turtlebot", "office")
    scene = viser_server.scene
    for frame in ("camera_depth_frame", *(f"ultrasonic_{i}" for i in range(7))):
        assert scene.get_handle_by_name(f"/robot/sensors/{frame}") is not None, frame
    assert scene.get_handle_by_name("/robot/sensors/imu_link") is None  # inside the body


def test_crowbot_leds_and_buzzer(viser_server):
    view = SceneView(viser_server, "crowbot", "light_arena")
    state = ViewState(pose=(1.0, 1.0, 0.0), leds_rgb=(0, 255, 0), buzzer_until_s=2.0)
    state.time_s = 1.5
    view.draw(state)
    scene = viser_server.scene
    assert all(
        tuple(scene.get_handle_by_name(f"/robot/led_{i}").color) == (0, 255, 0) for i in range(4)
    )
    # Its sensors are drawn from the start: the ultrasonic ranger and the two light sensors.
    ranger = scene.get_handle_by_name("/robot/sensors/Distance_0")
    assert tuple(ranger.position[:2]) == pytest.approx((0.05, 0.0))
    assert scene.get_handle_by_name("/robot/sensors/Light_1") is not None
    assert scene.get_handle_by_name("/robot/buzzer").visible
    state.time_s = 2.5
    view.draw(state)
    assert not scene.get_handle_by_name("/robot/buzzer").visible


def test_a_click_on_the_office_floor_sets_a_goal_facing_away_from_the_robot(viser_server):
    controls = SentCommands()
    view = SceneView(viser_server, "turtlebot", "office", controls)
    view.draw(ViewState(pose=(2.0, 1.0, 0.0)))
    click = SimpleNamespace(ray_origin=(3.0, 1.0, 4.0), ray_direction=(0.0, 0.6, -0.8))
    view._clicked(click)  # the callback viser calls for a scene click
    assert controls.goals == [pytest.approx((3.0, 4.0, math.atan2(3.0, 1.0)))]
    view._clicked(SimpleNamespace(ray_origin=(3, 1, 4), ray_direction=(0, 0.6, 0.8)))  # sky
    view._clicked(SimpleNamespace(ray_origin=(30, 1, 4), ray_direction=(0, 0, -1)))  # outside
    view.stop_controls()
    view._clicked(click)
    assert len(controls.goals) == 1
    assert floor_point((0, 0, 2), (1, 0, -1)) == pytest.approx((2.0, 0.0))


def test_dragging_the_lamp_moves_it_within_the_arena(viser_server):
    controls = SentCommands()
    view = SceneView(viser_server, "crowbot", "light_arena", controls)
    gizmo = viser_server.scene.get_handle_by_name("/lights/lamp")
    assert gizmo is not None and "lamp" in view.lights.nodes

    def drag(phase, x, y):
        view.lights._dragged("lamp", SimpleNamespace(phase=phase, target=SimpleNamespace(
            position=(x, y, 0.1))))  # fmt: skip

    drag("start", 1.0, 1.6)
    view.lights.update(view.world.lights)  # the simulation's echo does not fight the hand
    drag("end", 2.7, 0.4)
    assert controls.lights[-1] == ("lamp", 2.0, 0.4)  # clipped to the 2 m arena
    assert "lamp" not in view.lights.dragging


def test_a_replay_draws_the_time_asked_for_and_plays(viser_server, crowbot_run):
    recording = load_recording(crowbot_run / RECORDING_FILE)
    view = SceneView(viser_server, "crowbot", "light_arena")
    player = ReplayPlayer(viser_server, view, recording)
    try:
        wait_until(lambda: player.shown_s == 0.0)
        player.seek(1.5)
        wait_until(lambda: player.shown_s == 1.5)
        expected = recording.state_at(1.5).pose
        robot = viser_server.scene.get_handle_by_name("/robot")
        assert tuple(robot.position[:2]) == pytest.approx(expected[:2])
        assert tuple(viser_server.scene.get_handle_by_name("/robot/led_0").color) == (255, 0, 0)
        player.seek(0.0)
        player.set_playing(True)
        wait_until(lambda: (player.shown_s or 0.0) > 0.2)
        player.set_playing(False)
        assert player.play_button.label == "Play"
    finally:
        player.close()


def test_a_live_run_is_followed_from_its_telemetry_to_its_end(viser_server, launcher, tmp_path):
    telemetry = RunTelemetry("live")
    spec = crowbot_spec(duration_s=1.5, clock=Clock.REALTIME)  # lockstep outruns 30 Hz frames
    run = Run(spec, launcher, tmp_path / "run", observer=telemetry)
    view = SceneView(viser_server, "crowbot", "light_arena", run.command)
    worker = threading.Thread(target=run.execute)

    async def drag_the_lamp() -> None:
        while run.time_s < 0.5:
            await asyncio.sleep(0.01)
        view.lights._dragged("lamp", SimpleNamespace(phase="end", target=SimpleNamespace(
            position=(1.5, 0.5, 0.1))))  # fmt: skip

    async def main() -> ViewState:
        worker.start()
        lights = lambda: run.sim.lights if run.sim is not None else None  # noqa: E731
        feed = asyncio.create_task(follow_live(view, telemetry, lights))
        await drag_the_lamp()
        return await feed

    state = asyncio.run(main())
    worker.join()
    lamp = run.sim.lights[0]
    assert (lamp.x, lamp.y) == (1.5, 0.5)  # the drag reached the simulation...
    assert state.lights == run.sim.lights  # ...and came back to the view
    assert tuple(view.lights.nodes["lamp"].position[:2]) == pytest.approx((1.5, 0.5))
    assert state.time_s == pytest.approx(1.5, abs=0.1)
    assert state.leds_rgb == (255, 0, 0)
    robot = viser_server.scene.get_handle_by_name("/robot")
    assert tuple(robot.position[:2]) == pytest.approx(state.pose[:2])
    assert len(state.trail) >= 5  # a point per centimetre of the ~7 cm it rolled
    assert state.version > 30  # /tf alone comes at 30 Hz
    assert telemetry.viewer_count == 0  # the feed's viewer closed
