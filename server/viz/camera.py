"""Where the 3D view's camera looks: it opens on the robot where the world spawns it (close
enough that a 0.12 m CrowBot and a 0.45 m TurtleBot both fill a good part of the screen: ~6,000
and ~10,000 px at 1400x850), it can follow the robot as it drives
(a checkbox in viser's panel), and buttons frame the robot or the whole world again.

Framing is pure geometry (`robot_framing`, `world_framing`), testable without a server;
`CameraControls` puts the buttons in the panel and moves the cameras of the browsers watching.
Following shifts each camera by the robot's displacement, so an angle a person has orbited to
is kept while the robot drives.
"""

from __future__ import annotations

import math
import threading
from dataclasses import dataclass

ROBOT_VIEW_SIZES = 4.5  # [1] camera distance in robot sizes (its largest dimension)
ROBOT_VIEW_MIN_M = 0.7  # [m] but never closer than this: the robot's surroundings stay in view
ROBOT_VIEW_PITCH_RAD = math.radians(60.0)  # [rad] looking down at the robot, over the walls
AROUND_RAD = tuple(k * math.pi / 4 for k in (0, 1, -1, 2, -2, 3, -3, 4))  # camera turns tried
INSIDE_MARGIN_M = 0.1  # [m] the camera stands at least this far inside the world's bounds
WORLD_VIEW_BACK = 0.15  # [1] of the world's larger side: the world camera stands this far south
WORLD_VIEW_UP = 1.2  # [1] of the world's larger side, this high: looking down over the walls
FOLLOW_STEP_M = 0.005  # [m] a robot that moved less than this does not move the cameras
REFRAME_STEP_M = 0.1  # [m] the initial camera (for browsers yet to connect) moves in these steps


@dataclass(frozen=True, slots=True)
class Framing:
    """A camera placement: where it stands and the point it looks at, world frame [m]."""

    position: tuple[float, float, float]
    look_at: tuple[float, float, float]


def robot_framing(
    pose: tuple[float, float, float],
    size_m: float,
    height_m: float,
    bounds: tuple[float, float, float, float] | None = None,
) -> Framing:
    """Behind the robot (x [m], y [m], yaw [rad]) and above it, looking at its middle: the way
    it drives is up the screen. `size_m`: its largest dimension; `height_m`: its height. Within
    `bounds` (the world's), a camera that would stand outside the walls (a robot starting with
    its back to one) turns around the robot, 45 degrees at a time, until it stands inside."""
    x, y, yaw = pose
    distance = max(ROBOT_VIEW_SIZES * size_m, ROBOT_VIEW_MIN_M)
    back, up = distance * math.cos(ROBOT_VIEW_PITCH_RAD), distance * math.sin(ROBOT_VIEW_PITCH_RAD)
    target_z = height_m / 2
    for turn in AROUND_RAD:
        heading = yaw + turn
        camera_x, camera_y = x - back * math.cos(heading), y - back * math.sin(heading)
        if bounds is None or (
            bounds[0] + INSIDE_MARGIN_M <= camera_x <= bounds[2] - INSIDE_MARGIN_M
            and bounds[1] + INSIDE_MARGIN_M <= camera_y <= bounds[3] - INSIDE_MARGIN_M
        ):
            break
    else:
        camera_x, camera_y = x - back * math.cos(yaw), y - back * math.sin(yaw)
    return Framing((camera_x, camera_y, target_z + up), (x, y, target_z))


def world_framing(bounds: tuple[float, float, float, float]) -> Framing:
    """South of the world and high above it, looking at its centre: every wall in view."""
    min_x, min_y, max_x, max_y = bounds
    span = max(max_x - min_x, max_y - min_y)
    centre = ((min_x + max_x) / 2, (min_y + max_y) / 2)
    return Framing(
        (centre[0], min_y - WORLD_VIEW_BACK * span, WORLD_VIEW_UP * span),
        (centre[0], centre[1], 0.0),
    )


def _place(client, framing: Framing) -> None:
    with client.atomic():
        client.camera.position = framing.position
        client.camera.look_at = framing.look_at


class CameraControls:
    """The panel's camera folder on `server` (a viser.ViserServer); `follow(pose)` after every
    drawn pose."""

    def __init__(
        self,
        server,
        start_pose: tuple[float, float, float],
        size_m: float,
        height_m: float,
        bounds: tuple[float, float, float, float],
    ) -> None:
        self.server = server
        self.size_m, self.height_m, self.bounds = size_m, height_m, bounds
        self.pose = start_pose
        self._followed: tuple[float, float] | None = None  # robot x, y the cameras last moved to
        self._lock = threading.Lock()
        self._set_initial(start_pose)
        with server.gui.add_folder("Camera"):
            self.follow_box = server.gui.add_checkbox(
                "Follow robot", initial_value=False, hint="Keep the robot in the middle"
            )
            self.robot_button = server.gui.add_button("Frame robot", icon="focus-centered")
            self.world_button = server.gui.add_button("Frame world", icon="world")
        self.robot_button.on_click(lambda event: self.frame_robot(event.client))
        self.world_button.on_click(lambda event: self.frame_world(event.client))
        self.follow_box.on_update(lambda _event: self._restart_following())

    def _set_initial(self, pose: tuple[float, float, float]) -> None:
        framing = robot_framing(pose, self.size_m, self.height_m, self.bounds)
        self.server.initial_camera.position = framing.position
        self.server.initial_camera.look_at = framing.look_at
        self._initial_on = (pose[0], pose[1])

    def frame_robot(self, client) -> None:
        if client is not None:
            _place(client, robot_framing(self.pose, self.size_m, self.height_m, self.bounds))

    def frame_world(self, client) -> None:
        if client is not None:
            _place(client, world_framing(self.bounds))

    def _restart_following(self) -> None:
        with self._lock:
            self._followed = (self.pose[0], self.pose[1]) if self.follow_box.value else None

    def follow(self, pose: tuple[float, float, float]) -> None:
        """The robot is at `pose` now: a browser that connects from now on opens on it (viser's
        initial camera; connected ones keep theirs); with Follow ticked, every camera moves as
        far as the robot did."""
        self.pose = pose
        framed = self._initial_on
        if math.hypot(pose[0] - framed[0], pose[1] - framed[1]) >= REFRAME_STEP_M:
            self._set_initial(pose)
        if not self.follow_box.value:
            return
        with self._lock:
            if self._followed is None:
                self._followed = (pose[0], pose[1])
                return
            dx, dy = pose[0] - self._followed[0], pose[1] - self._followed[1]
            if math.hypot(dx, dy) < FOLLOW_STEP_M:
                return
            self._followed = (pose[0], pose[1])
        for client in list(self.server.get_clients().values()):
            camera = client.camera
            position, look_at = camera.position, camera.look_at
            _place(
                client,
                Framing(
                    (position[0] + dx, position[1] + dy, position[2]),
                    (look_at[0] + dx, look_at[1] + dy, look_at[2]),
                ),
            )
