"""The unit meshes: closed, every face turned outward (three.js culls the back), rotations right."""

from __future__ import annotations

import math

import numpy as np
import pytest

from server.viz.meshes import transformed, unit_box, unit_cylinder, yaw_wxyz, yaw_wxyzs


def outward(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Per face: its normal's component along the direction from the centre to the face."""
    a, b, c = (vertices[faces[:, i]].astype(np.float64) for i in range(3))
    normals = np.cross(b - a, c - a)
    return np.einsum("ij,ij->i", normals, (a + b + c) / 3 - vertices.mean(axis=0))


@pytest.mark.parametrize("mesh", [unit_box(), unit_cylinder()], ids=["box", "cylinder"])
def test_every_face_points_outward_and_the_mesh_is_closed(mesh):
    vertices, faces = mesh
    assert (outward(vertices, faces) > 0).all()
    edges = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), 1)
    _, counts = np.unique(edges, axis=0, return_counts=True)
    assert (counts == 2).all()  # each edge shared by exactly two faces: no holes


def test_unit_sizes_and_a_wheel_turned_onto_its_axle():
    box, _ = unit_box()
    assert np.ptp(box, axis=0) == pytest.approx([1, 1, 1])
    cylinder, faces = unit_cylinder()
    assert np.ptp(cylinder, axis=0) == pytest.approx([2, 2, 1])
    wheel = transformed(cylinder, (0.02, 0.02, 0.01), (0.0, 0.04, 0.02), swap_yz=True)
    assert np.ptp(wheel, axis=0) == pytest.approx([0.04, 0.01, 0.04], abs=1e-6)
    assert wheel.mean(axis=0) == pytest.approx([0.0, 0.04, 0.02], abs=1e-6)
    assert (outward(wheel, faces) > 0).all()  # a rotation, not a mirror


def test_yaw_quaternions():
    assert yaw_wxyz(math.pi / 2) == pytest.approx((math.sqrt(0.5), 0, 0, math.sqrt(0.5)))
    turns = yaw_wxyzs(np.array([0.0, math.pi]))
    assert turns == pytest.approx(np.array([[1, 0, 0, 0], [0, 0, 0, 1]]))
