"""Light sources in the scene: a glowing bulb and a point light at each, where the simulation has
them now. A movable light (the light arena's lamp) gets a transform gizmo that slides it over the
floor; releasing it, and every DRAG_UPDATE_S while dragging, calls `on_move(name, x, y)` (the
view sends the live run a `Light` command), clipped to the world's bounds as the simulator
requires.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable

from server.sim.world import LightSource

BULB_RGB = (255, 236, 120)
BULB_RADIUS_M = 0.03  # [m]
GIZMO_SCALE_M = 0.25  # [m] arm length of the drag handles
LIGHT_INTENSITY_SCALE = 0.6  # [1] viser point-light intensity per unit of the world's intensity
DRAG_UPDATE_S = 0.1  # [s] the light follows a drag at 10 Hz; the release always lands


class LightMarkers:
    def __init__(
        self,
        scene,
        lights: tuple[LightSource, ...],
        bounds: tuple[float, float, float, float],
        on_move: Callable[[str, float, float], None] | None = None,
    ) -> None:
        self.scene = scene
        self.bounds = bounds
        self.on_move = on_move
        self.nodes: dict[str, object] = {}
        self.dragging: set[str] = set()
        self._lock = threading.Lock()
        self._last_sent: dict[str, float] = {}
        self._shown: dict[str, tuple[float, float, float]] = {}
        for light in lights:
            self._add(light)

    def _add(self, light: LightSource) -> None:
        name = f"/lights/{light.name}"
        position = (light.x, light.y, light.z)
        if light.movable and self.on_move is not None:
            root = self.scene.add_transform_controls(
                name,
                scale=GIZMO_SCALE_M,
                active_axes=(True, True, False),
                disable_rotations=True,
                depth_test=False,
                position=position,
            )
            root.on_update(lambda event, light_name=light.name: self._dragged(light_name, event))
        else:
            root = self.scene.add_frame(name, show_axes=False, position=position)
        self.scene.add_icosphere(f"{name}/bulb", radius=BULB_RADIUS_M, color=BULB_RGB)
        self.scene.add_light_point(
            f"{name}/light", color=BULB_RGB, intensity=LIGHT_INTENSITY_SCALE * light.intensity
        )
        self.nodes[light.name] = root
        self._shown[light.name] = position

    def _dragged(self, name: str, event) -> None:
        with self._lock:
            if event.phase == "start":
                self.dragging.add(name)
            elif event.phase == "end":
                self.dragging.discard(name)
            now = time.monotonic()
            due = now - self._last_sent.get(name, 0.0) >= DRAG_UPDATE_S
            if event.phase != "end" and not due:
                return
            self._last_sent[name] = now
        x, y = float(event.target.position[0]), float(event.target.position[1])
        min_x, min_y, max_x, max_y = self.bounds
        x, y = min(max(x, min_x), max_x), min(max(y, min_y), max_y)
        if self.on_move is not None:
            self.on_move(name, x, y)

    def update(self, lights: tuple[LightSource, ...]) -> None:
        """Place the lights where the simulation has them (not one being dragged: the hand
        wins until it lets go)."""
        for light in lights:
            node = self.nodes.get(light.name)
            if node is None:
                self._add(light)
                continue
            position = (light.x, light.y, light.z)
            if light.name in self.dragging or self._shown.get(light.name) == position:
                continue
            self._shown[light.name] = position
            node.position = position
