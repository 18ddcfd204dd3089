"""ROS 2's tf_transformations: the same numbers as ROS 1's tf.transformations (one shared
implementation), the documented values of the ROS 2 package, and its tuple results."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from sandbox.host import install_ros_compat
from sandbox.msgs import get_message_class
from tests.ros2libs.loading import load_ros2_package

install_ros_compat()
import tf.transformations as ros1  # noqa: E402

ros2 = load_ros2_package("tf_transformations")
RNG = np.random.default_rng(7)
ANGLES = [tuple((RNG.random(3) - 0.5) * 2 * math.pi) for _ in range(30)]


def test_every_public_function_of_ros1_is_there() -> None:
    assert set(ros1.__all__) <= set(dir(ros2))
    for name in ("euler_matrix", "quaternion_matrix", "translation_matrix",
                 "concatenate_matrices", "euler_from_matrix", "quaternion_slerp"):  # fmt: skip
        assert getattr(ros2, name) is getattr(ros1, name)


@pytest.mark.parametrize("axes", sorted(ros2._AXES2TUPLE))
def test_euler_round_trips_agree_with_ros1(axes: str) -> None:
    for angles in ANGLES:
        q2 = ros2.quaternion_from_euler(*angles, axes=axes)
        assert isinstance(q2, tuple) and len(q2) == 4
        assert all(type(value) is float for value in q2)
        assert np.allclose(q2, ros1.quaternion_from_euler(*angles, axes=axes))
        assert np.allclose(
            ros2.euler_from_quaternion(q2, axes), ros1.euler_from_quaternion(q2, axes)
        )


def test_known_values_of_the_ros2_package() -> None:
    assert np.allclose(ros2.quaternion_from_euler(1, 2, 3, "ryxz"),
                       [0.310622, -0.718287, 0.444435, 0.435953])  # fmt: skip
    assert np.allclose(ros2.quaternion_about_axis(0.123, (1, 0, 0)), [0.06146124, 0, 0, 0.99810947])
    assert np.allclose(ros2.euler_from_quaternion([0.06146124, 0, 0, 0.99810947]), [0.123, 0, 0])
    assert np.allclose(ros2.quaternion_multiply([1, -2, 3, 4], [-5, 6, 7, 8]), [-44, -14, 48, 28])
    q = ros2.quaternion_from_matrix(ros2.rotation_matrix(0.123, (1, 2, 3)))
    assert np.allclose(q, [0.0164262, 0.0328524, 0.0492786, 0.9981095])
    assert np.allclose(np.sum(ros2.euler_matrix(1, 2, 3, "syxz")[0]), -1.34786452)


def test_quaternion_from_matrix_gives_w_of_at_least_zero() -> None:
    for angles in ANGLES:
        matrix = ros2.euler_matrix(*angles)
        q = ros2.quaternion_from_matrix(matrix)
        assert q[3] >= 0.0
        expected = Rotation.from_matrix(matrix[:3, :3]).as_quat()
        assert abs(abs(float(np.dot(q, expected))) - 1.0) < 1e-12
        assert np.allclose(ros2.quaternion_matrix(q), matrix)


def test_a_yaw_the_way_ros2_courses_build_and_read_it() -> None:
    q = ros2.quaternion_from_euler(0.0, 0.0, 2.5)
    x, y, z, w = q  # as courses unpack it into a geometry_msgs/Quaternion
    assert (x, y) == (0.0, 0.0) and w == pytest.approx(math.cos(1.25))
    assert ros2.euler_from_quaternion([x, y, z, w])[2] == pytest.approx(2.5)
    inverse = ros2.quaternion_inverse(q)
    assert np.allclose(ros2.quaternion_multiply(q, inverse), [0, 0, 0, 1])
    moved = ros2.concatenate_matrices(ros2.translation_matrix([1, 2, 0]), ros2.quaternion_matrix(q))
    assert np.allclose(moved @ [1, 0, 0, 1], [1 + math.cos(2.5), 2 + math.sin(2.5), 0, 1])


def test_a_message_instead_of_a_list_gets_the_shared_sentence() -> None:
    quaternion = get_message_class("geometry_msgs/msg/Quaternion")(w=1.0)
    with pytest.raises(TypeError, match=r"geometry_msgs/msg/Quaternion message.*\[q\.x, q\.y"):
        ros2.euler_from_quaternion(quaternion)
