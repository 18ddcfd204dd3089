"""Where the camera looks: on the robot from behind and above, inside the world's walls, the
whole world on request, and following the robot's moves for every browser watching."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from server.viz.camera import CameraControls, robot_framing, world_framing

OFFICE = (0.0, 0.0, 8.0, 6.0)


def test_the_robot_is_framed_from_behind_and_above() -> None:
    framing = robot_framing((2.0, 3.0, 0.0), size_m=0.45, height_m=0.45)
    assert framing.look_at == pytest.approx((2.0, 3.0, 0.225))
    x, y, z = framing.position
    assert x < 2.0 and y == pytest.approx(3.0) and z > 1.0  # behind (it faces +x), above
    distance = math.dist(framing.position, framing.look_at)
    assert 1.5 < distance < 3.0  # close: the robot fills a good part of the screen
    small = robot_framing((2.0, 3.0, 0.0), size_m=0.12, height_m=0.06)
    assert math.dist(small.position, small.look_at) < distance


def test_a_robot_with_its_back_to_a_wall_is_framed_from_inside() -> None:
    # The office's start: (2.0, 1.3) facing north, the outer wall 1.3 m behind it.
    framing = robot_framing((2.0, 1.3, math.pi / 2), 0.45, 0.45, OFFICE)
    x, y, _ = framing.position
    assert 0.0 < x < 8.0 and 0.0 < y < 6.0
    assert framing.look_at[:2] == pytest.approx((2.0, 1.3))


def test_the_world_is_framed_whole() -> None:
    framing = world_framing(OFFICE)
    assert framing.look_at == (4.0, 3.0, 0.0)
    assert framing.position[1] < 0.0 and framing.position[2] > 8.0


class FakeClient:
    """A browser's camera as viser's ClientHandle shows it."""

    def __init__(self, position, look_at) -> None:
        self.camera = SimpleNamespace(position=np.array(position), look_at=np.array(look_at))

    def atomic(self):
        import contextlib

        return contextlib.nullcontext()


def test_following_moves_every_camera_as_far_as_the_robot(viser_server, monkeypatch) -> None:
    controls = CameraControls(viser_server, (1.0, 1.0, 0.0), 0.45, 0.45, OFFICE)
    client = FakeClient((0.0, 0.0, 2.0), (1.0, 1.0, 0.2))
    monkeypatch.setattr(viser_server, "get_clients", lambda: {1: client})
    controls.follow((1.5, 1.0, 0.0))
    assert tuple(client.camera.position) == (0.0, 0.0, 2.0)  # not ticked: the camera stays
    controls.follow_box.value = True
    controls._restart_following()
    controls.follow((1.5, 1.2, 0.3))  # 0.2 m north of where it was when the box was ticked
    assert tuple(client.camera.position) == pytest.approx((0.0, 0.2, 2.0))
    assert tuple(client.camera.look_at) == pytest.approx((1.0, 1.2, 0.2))
    controls.follow((1.501, 1.2, 0.3))  # less than FOLLOW_STEP_M: the camera rests
    assert tuple(client.camera.position) == pytest.approx((0.0, 0.2, 2.0))
    controls.frame_world(client)
    assert tuple(client.camera.look_at) == (4.0, 3.0, 0.0)
    controls.frame_robot(client)
    assert tuple(client.camera.look_at[:2]) == pytest.approx((1.501, 1.2))
