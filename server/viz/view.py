"""One run's 3D view on one ViserServer: the world, the robot, the overlays and the lights put
together under a lighting that shades them and that software WebGL draws at a few frames a
second (viser's default lights without shadows and an ambient light, no environment map: with
it Chromium's SwiftShader took 12-20 s a frame at 1400x850 and showed a washed-out, near-white
scene meanwhile), the panel (the run's state and time,
the camera folder of camera.py, the layer toggles of layers.py), `draw(state)` to show a
`ViewState`, and the run's controls wired to the scene (a click
on the floor of a mapped world sends a `Goal`; dragging a movable light sends a `Light`: typed
commands, server/runs/commands.py, handed to `send`, which the manager binds to
`RunService.command` for this run).

Who may use the controls is settled before anyone reaches this server: the proxy admits only the
run's owner and instructors, the same people the run's control routes accept.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable

import numpy as np

from server.runs.commands import Goal, Light, RunCommand
from server.sim.registry import get_robot
from server.sim.world import load_world
from server.viz.camera import CameraControls
from server.viz.layers import Layer, LayerToggles
from server.viz.lights import LightMarkers
from server.viz.overlays import Overlays
from server.viz.rays import reading_key, sensor_drawings
from server.viz.robot_drawing import RobotDrawing
from server.viz.view_state import ViewState
from server.viz.world_scene import draw_world

log = logging.getLogger("robodojo.viz")
SENSOR_HEIGHT_FRACTION = 0.6  # [1] of the robot's height: where rays and scan points are drawn
AMBIENT_INTENSITY = 1.2  # [1] fills the faces the default lights miss (else they go black)
BACKGROUND_RGB = (206, 212, 222)  # a pale blue-grey sky: the floor's edge reads against it


# Sends a command to the run on show: False (or an error) when the run has ended.
CommandSink = Callable[[RunCommand], object]


def floor_point(origin, direction) -> tuple[float, float] | None:
    """Where a click's ray meets the floor (z = 0), or None if it points upward."""
    if direction[2] >= -1e-9:
        return None
    t = -origin[2] / direction[2]
    return origin[0] + t * direction[0], origin[1] + t * direction[1]


def _same(old: tuple | None, new: tuple) -> bool:
    return old is not None and old[0] is new[0] and old[1] == new[1]


class SceneView:
    def __init__(
        self, server, robot_id: str, world_id: str, send: CommandSink | None = None
    ) -> None:
        self.server = server
        self.robot = get_robot(robot_id)
        self.world = load_world(world_id)
        self.sensors = self.robot.build_sensors()
        self.send = send  # None: a replay, or a run that has ended
        scene = server.scene
        scene.set_up_direction("+z")
        scene.configure_environment_map(hdri=None)
        scene.configure_default_lights(enabled=True, cast_shadow=False)
        scene.add_light_ambient("/ambient", intensity=AMBIENT_INTENSITY)
        scene.set_background_image(np.full((2, 2, 3), BACKGROUND_RGB, dtype=np.uint8))
        self.status = server.gui.add_markdown("")
        self.world_nodes = draw_world(scene, self.world)
        self.robot_drawing = RobotDrawing(scene, self.robot)
        spawn = self.world.spawns[0]
        start = (spawn.x, spawn.y, spawn.yaw)
        self.robot_drawing.update(start, None, False, {})
        g = self.robot.geometry
        self.camera = CameraControls(
            server, start, max(g.length_m, g.width_m, g.height_m), g.height_m, self.world.bounds
        )
        self.overlays = Overlays(scene, SENSOR_HEIGHT_FRACTION * g.height_m)
        self.lights = LightMarkers(
            scene,
            self.world.lights,
            self.world.bounds,
            on_move=self._move_light if send is not None else None,
        )
        self.layers = LayerToggles(server.gui, self._layers())
        self.pose: tuple[float, float, float] | None = None
        self._reading_keys: dict[str, tuple] = {}  # topic -> reading_key last drawn
        if send is not None and self.world.grid_map is not None:
            scene.on_click()(self._clicked)

    def _layers(self) -> list[Layer]:
        node = self.server.scene.get_handle_by_name
        world = [
            node(name)
            for name in self.world_nodes.names
            if name not in ("/world/floor", "/world/grid", "/world/map")
            and not name.startswith("/world/tape_")
        ]
        overlays = self.overlays
        return [
            Layer("Walls and furniture", tuple(world)),
            Layer("Floor grid", (node("/world/grid"),)),
            Layer("Map", (node("/world/map"),) if self.world_nodes.has_map else ()),
            Layer("Sensor readings", (overlays.readings_root,)),
            Layer("Trail", (overlays.trail_root,)),
            Layer("Plan and goal", (overlays.route_root,)),
            Layer("Lights", tuple(self.lights.nodes.values())),
        ]

    # ----------------------------------------------------------------------------- drawing
    def draw(self, state: ViewState) -> None:
        """Show `state` (call from one thread at a time)."""
        changed = {
            topic
            for topic, (_, msg) in state.latest.items()
            if not _same(self._reading_keys.get(topic), reading_key(state, self.robot, msg))
        }
        drawings = sensor_drawings(state, self.robot, self.sensors, self.world, changed)
        for topic in changed:
            self._reading_keys[topic] = reading_key(state, self.robot, state.latest[topic][1])
        with self.server.atomic():
            self.robot_drawing.update(
                state.pose, state.leds_rgb, state.buzzer_on, state.sensor_frames
            )
            self.overlays.draw_sensors(drawings, set(state.latest))
            self.overlays.draw_trail(state.trail)
            self.overlays.draw_path(state.plan, state.pose, state.lookahead)
            self.overlays.draw_goal(state.goal)
            if state.lights:
                self.lights.update(state.lights)
        self.pose = state.pose
        if state.pose is not None:
            self.camera.follow(state.pose)

    def set_status(self, text: str) -> None:
        """The panel's first line: the run's state and time (live.py, replay.py, manager.py)."""
        self.status.content = text

    # ----------------------------------------------------------------------------- controls
    def stop_controls(self) -> None:
        """The run ended: clicks and drags do nothing from now on."""
        self.send = None

    def _clicked(self, event) -> None:
        point = floor_point(event.ray_origin, event.ray_direction)
        if point is None or not self.world.in_bounds(*point):
            return
        x, y = point
        yaw = 0.0
        if self.pose is not None:  # face the way the robot has to go to get there
            yaw = math.atan2(y - self.pose[1], x - self.pose[0])
        self._tell(Goal(x, y, yaw))

    def _move_light(self, name: str, x: float, y: float) -> None:
        self._tell(Light(x, y, name))

    def _tell(self, command: RunCommand) -> None:
        send = self.send
        if send is None:
            return
        try:
            sent = send(command)
        except Exception as error:  # a run that just ended, or a state that refuses it
            log.info("%s not sent: %s", command, error)
            return
        if sent is False:
            log.info("%s not sent: the run is not running", command)
