"""Layer toggles in the 3D view's panel: one checkbox per kind of thing drawn (walls and
furniture, the floor grid, the map, sensor readings, trail, plan and goal, lights). A layer is
the scene nodes given for it; hiding a parent node hides everything below it (three.js), so the
drawings keep showing and hiding their own nodes without knowing about the toggles.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass


@dataclass(frozen=True, slots=True)
class Layer:
    label: str  # the checkbox's label in the panel
    nodes: tuple[object, ...]  # viser scene node handles shown or hidden together


class LayerToggles:
    def __init__(self, gui, layers: Sequence[Layer]) -> None:
        self.layers = {layer.label: layer for layer in layers if layer.nodes}
        self.boxes = {}
        with gui.add_folder("Layers"):
            for label, layer in self.layers.items():
                box = gui.add_checkbox(label, initial_value=True)
                box.on_update(lambda _event, layer=layer, box=box: self.show(layer, box.value))
                self.boxes[label] = box

    @staticmethod
    def show(layer: Layer, visible: bool) -> None:
        for node in layer.nodes:
            node.visible = visible
