"""The panel's layer toggles hide and show whole kinds of drawing."""

from __future__ import annotations

import math

from server.viz.view import SceneView
from server.viz.view_state import ViewState


def test_every_layer_of_the_office_hides_and_shows(viser_server) -> None:
    view = SceneView(viser_server, "turtlebot", "office")
    view.draw(ViewState(pose=(2.0, 1.3, math.pi / 2), plan=[(2.0, 1.3), (3.0, 3.0)]))
    labels = set(view.layers.boxes)
    assert {"Walls and furniture", "Floor grid", "Map", "Sensor readings", "Trail"} <= labels
    assert "Plan and goal" in labels
    for label, layer in view.layers.layers.items():
        view.layers.show(layer, False)
        assert all(not node.visible for node in layer.nodes), label
        view.layers.show(layer, True)
        assert all(node.visible for node in layer.nodes), label
    plan = view.layers.layers["Plan and goal"]
    assert plan.nodes == (viser_server.scene.get_handle_by_name("/route"),)


def test_a_world_without_a_map_or_lights_offers_no_such_toggle(viser_server) -> None:
    view = SceneView(viser_server, "crowbot", "wall_approach")
    assert "Map" not in view.layers.boxes and "Lights" not in view.layers.boxes
