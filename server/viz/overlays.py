"""Everything drawn over the world that changes while a run goes: each sensor's reading (cones
and beams shaded by their reading, scan points coloured by range: near is red, far is teal), the
robot's trail, the planned path with its lookahead point, and the goal. Each kind hangs below its
own parent node (/robot/readings, /trail, /route), so a layer toggle hides it whole.

A node is made the first time it has something to show and updated in place after; the trail is
cut into sealed chunks so a long run sends only its newest chunk each frame, not 20 000 points.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from server.viz.meshes import transformed, unit_cylinder, yaw_wxyz
from server.viz.rays import SensorDrawing

SENSOR_NODE = "/robot/readings"  # below the robot: readings are drawn in its frame
TRAIL_NODE, ROUTE_NODE = "/trail", "/route"  # the trail's chunks; the plan, lookahead and goal
# Range colours, near to far: (fraction of FAR_M, RGB). No blue: that is the robot's colour.
RANGE_STOPS = (
    (0.0, (230, 30, 30)),
    (0.25, (255, 140, 0)),
    (0.5, (235, 215, 0)),
    (0.75, (60, 190, 60)),
    (1.0, (0, 170, 170)),
)
SCAN_FAR_M = 4.0  # [m] a scan point this far or further gets the last colour
# A ranger's cone, shaded by its reading: near is its own colour, at or past FAR_M pale.
RANGER_NEAR_RGB = {"ultrasound": (240, 100, 0), "infrared": (220, 0, 40)}
RANGER_FAR_RGB = (250, 220, 150)
RANGER_FAR_M = 1.5  # [m]
TRAIL_RGB = (150, 40, 190)
PLAN_RGB = (20, 160, 60)
GOAL_RGB = (220, 30, 160)
LOOKAHEAD_RGB = (255, 200, 0)
RAY_THICKNESS_M = 0.008  # [m]
TRAIL_THICKNESS_M = 0.012  # [m]
PLAN_THICKNESS_M = 0.016  # [m]
SCAN_POINT_SIZE_M = 0.03  # [m]
OVERLAY_LIFT_M = 0.01  # [m] trail, plan and goal float this far above the floor
TRAIL_CHUNK_POINTS = 64  # [-] points per sealed trail node: the tail resent per frame <= 1.5 KiB
GOAL_ARROW_M = 0.3  # [m] length of the line showing the goal's yaw
GOAL_DISC_M = 0.08  # [m] radius of the goal's disc
LOOKAHEAD_M = 0.35  # [m] along the plan, when no node publishes its own `lookahead` (the
# Stanley reference's T_2 distance, server/exercises/reference/turtlebot_stanley.py)


def node_name(topic: str) -> str:
    """A topic as one scene-node name segment ("ultrasonic/range_0" -> "ultrasonic_range_0")."""
    return topic.strip("/").replace("/", "_") or "_"


def range_colours(distances_m: np.ndarray, far_m: float = SCAN_FAR_M) -> np.ndarray:
    """(N, 3) uint8 colours of distances [m] along RANGE_STOPS (0 m red ... far_m teal)."""
    fraction = np.clip(np.asarray(distances_m, dtype=np.float64) / far_m, 0.0, 1.0)
    stops = np.array([stop for stop, _ in RANGE_STOPS])
    rgb = np.array([colour for _, colour in RANGE_STOPS], dtype=np.float64)
    channels = [np.interp(fraction, stops, rgb[:, i]) for i in range(3)]
    return np.stack(channels, axis=-1).round().astype(np.uint8).reshape(-1, 3)


def ranger_colours(segments: np.ndarray, kind: str) -> np.ndarray:
    """(K, 2, 3) uint8: each segment of a cone shaded by its length (the reading)."""
    segments = np.asarray(segments, dtype=np.float64).reshape(-1, 4)
    lengths = np.hypot(segments[:, 2] - segments[:, 0], segments[:, 3] - segments[:, 1])
    t = np.clip(lengths / RANGER_FAR_M, 0.0, 1.0)[:, None]
    near = np.array(RANGER_NEAR_RGB.get(kind, RANGER_NEAR_RGB["ultrasound"]), dtype=np.float64)
    rgb = (1 - t) * near + t * np.array(RANGER_FAR_RGB, dtype=np.float64)
    return np.repeat(rgb.round().astype(np.uint8)[:, None, :], 2, axis=1)


def segments_3d(segments: np.ndarray, z_m: float) -> np.ndarray:
    """(K, 4) floor segments -> (K, 2, 3) at height `z_m` [m]."""
    segments = np.asarray(segments, dtype=np.float32).reshape(-1, 4)
    out = np.empty((len(segments), 2, 3), dtype=np.float32)
    out[:, 0, :2], out[:, 1, :2] = segments[:, :2], segments[:, 2:]
    out[:, :, 2] = z_m
    return out


def polyline_segments(points: Sequence[tuple[float, float]], z_m: float) -> np.ndarray:
    """Consecutive points joined: (N-1, 2, 3)."""
    xy = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    return segments_3d(np.column_stack([xy[:-1], xy[1:]]), z_m)


def lookahead_point(
    plan: Sequence[tuple[float, float]], x: float, y: float, distance_m: float = LOOKAHEAD_M
) -> tuple[float, float] | None:
    """The point `distance_m` [m] along `plan` past its point nearest (x, y) (the plan's end if it
    is shorter), as a pure pursuit or Stanley tracker picks its target (Coulter 1992)."""
    path = np.asarray(plan, dtype=np.float64).reshape(-1, 2)
    if len(path) == 0:
        return None
    nearest = int(np.argmin(np.hypot(path[:, 0] - x, path[:, 1] - y)))
    remaining = distance_m
    for i in range(nearest, len(path) - 1):
        step = float(np.hypot(*(path[i + 1] - path[i])))
        if step >= remaining:
            t = remaining / step
            return tuple(path[i] + t * (path[i + 1] - path[i]))
        remaining -= step
    return float(path[-1, 0]), float(path[-1, 1])


class Overlays:
    def __init__(self, scene, sensor_height_m: float) -> None:
        self.scene = scene
        self.sensor_height_m = sensor_height_m  # [m] rays are drawn at this height
        # The parents the layer toggles hide (layers.py).
        self.readings_root = scene.add_frame(SENSOR_NODE, show_axes=False)
        self.trail_root = scene.add_frame(TRAIL_NODE, show_axes=False)
        self.route_root = scene.add_frame(ROUTE_NODE, show_axes=False)
        self.sensor_nodes: dict[str, tuple[object, str]] = {}
        self._trail_sealed: list[object] = []
        self._trail_tail = None
        self._trail_first: tuple[float, float] | None = None
        self._plan_key = None
        self._plan_node = None
        self._lookahead_node = None
        self._goal_node = None
        self._goal_shown = None

    # ----------------------------------------------------------------------------- sensors
    def draw_sensors(self, drawings: dict[str, SensorDrawing], present: set[str]) -> None:
        """Update the readings that changed (`drawings`, robot frame: the nodes hang below
        /robot); hide those whose topic is not in `present` (a replay before its first one)."""
        for topic, drawing in drawings.items():
            name = f"{SENSOR_NODE}/{node_name(topic)}"
            if drawing.kind == "scan":
                points = np.column_stack(
                    [drawing.points, np.full(len(drawing.points), self.sensor_height_m)]
                ).astype(np.float32)
                colours = range_colours(np.hypot(drawing.points[:, 0], drawing.points[:, 1]))
                self._update(topic, name, "points", points, colours)
            else:
                segments = segments_3d(drawing.segments, self.sensor_height_m)
                colours = ranger_colours(drawing.segments, drawing.kind)
                self._update(topic, name, "segments", segments, colours)
        for topic, (node, _) in self.sensor_nodes.items():
            if topic not in present:
                node.visible = False

    def _update(self, topic: str, name: str, kind: str, data: np.ndarray, colour) -> None:
        known = self.sensor_nodes.get(topic)
        if len(data) == 0:
            if known is not None:
                known[0].visible = False
            return
        if known is not None:
            known[0].points = data
            known[0].colors = colour
            known[0].visible = True
            return
        if kind == "points":
            node = self.scene.add_point_cloud(
                name, data, colour, point_size=SCAN_POINT_SIZE_M, point_shape="circle"
            )
        else:
            node = self.scene.add_line_segments(name, data, colour, thickness=RAY_THICKNESS_M)
        self.sensor_nodes[topic] = (node, kind)

    # ----------------------------------------------------------------------------- trail
    def draw_trail(self, trail: Sequence[tuple[float, float]]) -> None:
        """Seal a chunk every TRAIL_CHUNK_POINTS points; start over if the trail's first point
        changed (the oldest points dropped, or a replay jumped back)."""
        first = trail[0] if len(trail) else None
        sealed_points = len(self._trail_sealed) * TRAIL_CHUNK_POINTS
        if first != self._trail_first or len(trail) < sealed_points:
            self.clear_trail()
            self._trail_first = first
            sealed_points = 0
        points = list(trail)
        while len(points) - sealed_points > TRAIL_CHUNK_POINTS:
            # The chunk shares its last point with the next one, so the line never breaks.
            chunk = points[sealed_points : sealed_points + TRAIL_CHUNK_POINTS + 1]
            index = len(self._trail_sealed)
            self._trail_sealed.append(
                self.scene.add_line_segments(
                    f"{TRAIL_NODE}/{index}",
                    polyline_segments(chunk, OVERLAY_LIFT_M),
                    TRAIL_RGB,
                    thickness=TRAIL_THICKNESS_M,
                )
            )
            sealed_points += TRAIL_CHUNK_POINTS
        tail = points[sealed_points:]
        if len(tail) < 2:
            if self._trail_tail is not None:
                self._trail_tail.visible = False
            return
        segments = polyline_segments(tail, OVERLAY_LIFT_M)
        if self._trail_tail is None:
            self._trail_tail = self.scene.add_line_segments(
                f"{TRAIL_NODE}/tail", segments, TRAIL_RGB, thickness=TRAIL_THICKNESS_M
            )
        else:
            self._trail_tail.points = segments
            self._trail_tail.visible = True

    def clear_trail(self) -> None:
        for node in self._trail_sealed:
            node.remove()
        self._trail_sealed = []
        if self._trail_tail is not None:
            self._trail_tail.visible = False
        self._trail_first = None

    # ----------------------------------------------------------------------------- path, goal
    def draw_path(
        self,
        plan: list[tuple[float, float]] | None,
        pose: tuple[float, float, float] | None,
        published_lookahead: tuple[float, float] | None,
    ) -> None:
        key = (id(plan), len(plan) if plan else 0)
        if key != self._plan_key:
            self._plan_key = key
            if plan and len(plan) >= 2:
                segments = polyline_segments(plan, OVERLAY_LIFT_M)
                if self._plan_node is None:
                    self._plan_node = self.scene.add_line_segments(
                        f"{ROUTE_NODE}/plan", segments, PLAN_RGB, thickness=PLAN_THICKNESS_M
                    )
                else:
                    self._plan_node.points = segments
                    self._plan_node.visible = True
            elif self._plan_node is not None:
                self._plan_node.visible = False
        point = published_lookahead
        if point is None and plan and pose is not None:
            point = lookahead_point(plan, pose[0], pose[1])
        if point is None:
            if self._lookahead_node is not None:
                self._lookahead_node.visible = False
            return
        position = (float(point[0]), float(point[1]), OVERLAY_LIFT_M + 0.03)
        if self._lookahead_node is None:
            self._lookahead_node = self.scene.add_icosphere(
                f"{ROUTE_NODE}/lookahead", radius=0.04, color=LOOKAHEAD_RGB, position=position
            )
        else:
            self._lookahead_node.position = position
            self._lookahead_node.visible = True

    def draw_goal(self, goal: tuple[float, float, float] | None) -> None:
        if goal == self._goal_shown:
            return
        self._goal_shown = goal
        if goal is None:
            if self._goal_node is not None:
                self._goal_node.visible = False
            return
        x, y, yaw = goal
        if self._goal_node is None:
            self._goal_node = self.scene.add_frame(f"{ROUTE_NODE}/goal", show_axes=False)
            vertices, faces = unit_cylinder()
            self.scene.add_mesh_simple(
                f"{ROUTE_NODE}/goal/disc",
                transformed(vertices, (GOAL_DISC_M, GOAL_DISC_M, 0.01), (0, 0, OVERLAY_LIFT_M)),
                faces,
                color=GOAL_RGB,
            )
            self.scene.add_line_segments(
                f"{ROUTE_NODE}/goal/heading",
                np.array([[[0.0, 0.0, OVERLAY_LIFT_M], [GOAL_ARROW_M, 0.0, OVERLAY_LIFT_M]]]),
                GOAL_RGB,
                thickness=PLAN_THICKNESS_M,
            )
        self._goal_node.position = (x, y, 0.0)
        self._goal_node.wxyz = yaw_wxyz(yaw)
        self._goal_node.visible = True
