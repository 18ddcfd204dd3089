"""Built-in nodes: trusted helpers the server runs beside the students' nodes, so an exercise can
focus on control as the papers do (003_4f92d1fa0a49ddae.txt section 5: map server, planner and
localization come from Nav2; the student writes the controller).

- `map_server`: the world's occupancy grid on `map` (nav_msgs/OccupancyGrid), once at start.
- `localization`: the robot's pose on `pose` (geometry_msgs/PoseStamped, frame "map") at 20 Hz:
  the true pose plus seeded Gaussian noise (`localization_noise_m`, `localization_noise_rad`).
- `waypoints`: the exercise's goals (`waypoints`: [(x, y, yaw), ...]) on `goal_pose`
  (PoseStamped), the next one each time the robot comes within `waypoint_tolerance_m`.
- `planner`: a path on `plan` (nav_msgs/Path) from the robot to each new `goal_pose`, by A* over
  the map with obstacles grown by the robot's radius, as Nav2's NavFn plans on its costmap.
- `teleop`: drives the robot from key presses (the Teleop command: up/down/left/right,
  as arrow keys in the browser), publishing a Twist on the robot's velocity topic at 10 Hz while
  a key is held and one zero Twist when all are released.

They run in the server process (no sandbox: they are our code), are called synchronously by
the run, and publish through the same topic bus, so students see them as ordinary nodes.
"""

from __future__ import annotations

import heapq
import math
from typing import TYPE_CHECKING

import numpy as np

from sandbox.msgs import Time
from sandbox.msgs.geometry_msgs import Point, Pose, PoseStamped, Quaternion
from sandbox.msgs.nav_msgs import MapMetaData, OccupancyGrid, Path
from sandbox.msgs.std_msgs import Header
from server.sim.geometry import yaw_quaternion

if TYPE_CHECKING:
    from server.runs.core import RunCore as Run  # built-ins are handed the run's core

LOCALIZATION_RATE_HZ = 20.0  # [Hz] as a Nav2 AMCL pose arrives
DEFAULT_TOLERANCE_M = 0.25  # [m] a waypoint counts as reached this close
OCCUPIED = 50  # cells at or above this occupancy (and unknown cells) are obstacles


def _pose_stamped(time_s: float, x: float, y: float, yaw: float) -> PoseStamped:
    return PoseStamped(
        header=Header(stamp=Time.from_sec(time_s), frame_id="map"),
        pose=Pose(
            position=Point(x=x, y=y),
            orientation=Quaternion(*yaw_quaternion(yaw)),
        ),
    )


class BuiltinNode:
    """Base: a name, the topics it listens to, and hooks the run calls."""

    name = "builtin"
    subscribes: tuple[str, ...] = ()
    publishes: tuple[tuple[str, str], ...] = ()  # (topic, ROS type), told to student nodes
    # Topics of `publishes` whose last message reaches later subscribers too: map_server's map
    # is latched in ROS 1 and TRANSIENT_LOCAL in Nav2's map_server (ROS 2).
    latched: tuple[str, ...] = ()
    rate_hz: float | None = None
    # False: the node publishes and receives ROS 1 objects (sandbox.msgs) and the host converts
    # them in a ROS 2 run. True: it speaks ROS 2 (sandbox.msgs2 objects, ROS 2 type names in
    # `publishes` and graph_subscriptions()) and is left out of ROS 1 runs.
    ros2_native = False

    def graph_subscriptions(self) -> tuple[tuple[str, str], ...]:
        """(topic, type) the node is listed as subscribing to in the run's graph, delivered
        like `subscribes`. A service server needs its request topic here: a client's
        wait_for_service looks for a subscriber of `__srv__/<service>`. (Topics known only in
        start() go to `run.bus.declare_listener(name, topic, type)` and `subscribes`.)"""
        return ()

    def listens_to(self, topic: str) -> bool:
        return topic in self.subscribes or any(t == topic for t, _ in self.graph_subscriptions())

    def start(self, run: Run) -> list[tuple[str, object]]:
        return []

    def on_message(self, run: Run, topic: str, message: object) -> list[tuple[str, object]]:
        return []

    def tick(self, run: Run) -> list[tuple[str, object]]:
        return []


class MapServer(BuiltinNode):
    name = "map_server"
    publishes = (("map", "nav_msgs/OccupancyGrid"),)
    latched = ("map",)

    def start(self, run: Run) -> list[tuple[str, object]]:
        grid = run.sim.world.grid_map
        if grid is None:
            return []
        message = OccupancyGrid(
            header=Header(stamp=Time.from_sec(0.0), frame_id="map"),
            info=MapMetaData(
                resolution=grid.resolution,
                width=grid.width,
                height=grid.height,
                origin=Pose(
                    position=Point(x=grid.origin_x, y=grid.origin_y),
                    orientation=Quaternion(*yaw_quaternion(grid.origin_yaw)),
                ),
            ),
            data=np.asarray(grid.data, dtype=np.int8).reshape(-1).tolist(),
        )
        return [("map", message)]


class Localization(BuiltinNode):
    name = "localization"
    publishes = (("pose", "geometry_msgs/PoseStamped"),)
    rate_hz = LOCALIZATION_RATE_HZ

    def start(self, run: Run) -> list[tuple[str, object]]:
        self.rng = np.random.default_rng([run.spec.seed, 0x10CA])
        self.noise_m = float(run.spec.params.get("localization_noise_m", 0.0))
        self.noise_rad = float(run.spec.params.get("localization_noise_rad", 0.0))
        return self.tick(run)

    def tick(self, run: Run) -> list[tuple[str, object]]:
        pose = run.sim.state.pose
        dx, dy = self.rng.normal(0.0, self.noise_m, 2) if self.noise_m else (0.0, 0.0)
        dyaw = self.rng.normal(0.0, self.noise_rad) if self.noise_rad else 0.0
        return [("pose", _pose_stamped(run.time_s, pose.x + dx, pose.y + dy, pose.yaw + dyaw))]


class Waypoints(BuiltinNode):
    name = "waypoints"
    publishes = (("goal_pose", "geometry_msgs/PoseStamped"),)
    rate_hz = 10.0  # [Hz] how often it checks whether the current goal is reached

    def start(self, run: Run) -> list[tuple[str, object]]:
        self.goals = [tuple(map(float, goal)) for goal in run.spec.params.get("waypoints", ())]
        self.tolerance = float(run.spec.params.get("waypoint_tolerance_m", DEFAULT_TOLERANCE_M))
        self.index = 0
        self.reached_at: list[float] = []
        return self._current(run)

    def _current(self, run: Run) -> list[tuple[str, object]]:
        if self.index >= len(self.goals):
            return []
        return [("goal_pose", _pose_stamped(run.time_s, *self.goals[self.index]))]

    def tick(self, run: Run) -> list[tuple[str, object]]:
        if self.index >= len(self.goals):
            return []
        pose = run.sim.state.pose
        x, y, _ = self.goals[self.index]
        if math.hypot(x - pose.x, y - pose.y) > self.tolerance:
            return []
        self.reached_at.append(run.time_s)
        self.index += 1
        return self._current(run)


class Planner(BuiltinNode):
    name = "planner"
    subscribes = ("goal_pose",)
    publishes = (("plan", "nav_msgs/Path"),)

    def start(self, run: Run) -> list[tuple[str, object]]:
        grid = run.sim.world.grid_map
        if grid is None:
            raise ValueError(f"the planner needs a map; world '{run.sim.world.id}' has none")
        self.grid = grid
        blocked = (grid.data >= OCCUPIED) | (grid.data < 0)
        radius_cells = math.ceil(run.sim.robot.geometry.body_radius_m / grid.resolution)
        self.blocked = _grow(blocked, radius_cells)
        return []

    def on_message(self, run: Run, topic: str, message: object) -> list[tuple[str, object]]:
        pose = run.sim.state.pose
        goal = message.pose.position
        cells = astar(self.blocked, self._cell(pose.x, pose.y), self._cell(goal.x, goal.y))
        path = Path(header=Header(stamp=Time.from_sec(run.time_s), frame_id="map"))
        path.poses = [_pose_stamped(run.time_s, *self._centre(row, col), 0.0) for row, col in cells]
        return [("plan", path)]

    def _cell(self, x: float, y: float) -> tuple[int, int]:
        g = self.grid
        col = int((x - g.origin_x) / g.resolution)
        row = int((y - g.origin_y) / g.resolution)
        return min(max(row, 0), g.height - 1), min(max(col, 0), g.width - 1)

    def _centre(self, row: int, col: int) -> tuple[float, float]:
        g = self.grid
        return g.origin_x + (col + 0.5) * g.resolution, g.origin_y + (row + 0.5) * g.resolution


def _grow(blocked: np.ndarray, radius_cells: int) -> np.ndarray:
    """Obstacles grown by a disc of `radius_cells` (the robot fits where the result is free)."""
    grown = blocked.copy()
    height, width = blocked.shape
    rows, cols = np.nonzero(blocked)
    for dr in range(-radius_cells, radius_cells + 1):
        for dc in range(-radius_cells, radius_cells + 1):
            if dr * dr + dc * dc > radius_cells * radius_cells:
                continue
            r, c = rows + dr, cols + dc
            inside = (r >= 0) & (r < height) & (c >= 0) & (c < width)
            grown[r[inside], c[inside]] = True
    return grown


def astar(
    blocked: np.ndarray, start: tuple[int, int], goal: tuple[int, int]
) -> list[tuple[int, int]]:
    """Shortest 8-connected path of free cells from `start` to `goal` (both included); [] when
    there is none. The start cell may be blocked (a robot touching a grown obstacle)."""
    if blocked[goal]:
        return []
    height, width = blocked.shape
    steps = [(-1, 0, 1.0), (1, 0, 1.0), (0, -1, 1.0), (0, 1, 1.0)] + [
        (dr, dc, math.sqrt(2.0)) for dr in (-1, 1) for dc in (-1, 1)
    ]
    best = {start: 0.0}
    came_from: dict[tuple[int, int], tuple[int, int]] = {}
    frontier = [(math.dist(start, goal), 0.0, start)]
    while frontier:
        _, cost, cell = heapq.heappop(frontier)
        if cell == goal:
            path = [cell]
            while cell in came_from:
                cell = came_from[cell]
                path.append(cell)
            return path[::-1]
        if cost > best.get(cell, math.inf):
            continue
        for dr, dc, length in steps:
            nxt = (cell[0] + dr, cell[1] + dc)
            if not (0 <= nxt[0] < height and 0 <= nxt[1] < width) or blocked[nxt]:
                continue
            new_cost = cost + length
            if new_cost < best.get(nxt, math.inf):
                best[nxt] = new_cost
                came_from[nxt] = cell
                heapq.heappush(frontier, (new_cost + math.dist(nxt, goal), new_cost, nxt))
    return []


TELEOP_SPEED_M_S = 0.1  # [m/s] forward/backward while an arrow key is held
TELEOP_TURN_RAD_S = 1.0  # [rad/s] left/right while an arrow key is held


class Teleop(BuiltinNode):
    name = "teleop"
    rate_hz = 10.0  # [Hz] a held key repeats, as a keyboard does

    def start(self, run: Run) -> list[tuple[str, object]]:
        from sandbox.msgs.geometry_msgs import Twist

        self.twist_class = Twist
        self.topic = run.velocity_topic
        if self.topic is None:
            raise ValueError(f"robot '{run.spec.robot}' has no velocity topic to drive")
        self.held: set[str] = set()
        self.was_moving = False
        return []

    def key(self, key: str, pressed: bool) -> None:
        """An arrow key (commands.TELEOP_KEYS, checked when the Teleop command was made)."""
        (self.held.add if pressed else self.held.discard)(key)

    def tick(self, run: Run) -> list[tuple[str, object]]:
        if not self.held and not self.was_moving:
            return []
        twist = self.twist_class()
        twist.linear.x = TELEOP_SPEED_M_S * (("up" in self.held) - ("down" in self.held))
        twist.angular.z = TELEOP_TURN_RAD_S * (("left" in self.held) - ("right" in self.held))
        self.was_moving = bool(self.held)
        return [(self.topic, twist)]


BUILTIN_NODES: dict[str, type[BuiltinNode]] = {
    cls.name: cls for cls in (MapServer, Localization, Waypoints, Planner, Teleop)
}
