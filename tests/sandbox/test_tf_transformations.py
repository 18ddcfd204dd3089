"""tf.transformations against scipy's Rotation (all 24 Euler conventions), against the values
documented in the module ROS ships, and against bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from sandbox.host import install_ros_compat
from sandbox.msgs.geometry_msgs import Quaternion

install_ros_compat()
import tf.transformations as T  # noqa: E402

ALL_AXES = sorted(T._AXES2TUPLE)
RNG = np.random.default_rng(12)
ANGLES = [tuple((RNG.random(3) - 0.5) * 2 * math.pi) for _ in range(40)]


def scipy_sequence(axes: str) -> str:
    """'sxyz' is scipy's extrinsic 'xyz'; 'rxyz' its intrinsic 'XYZ'."""
    return axes[1:] if axes[0] == "s" else axes[1:].upper()


def test_there_are_24_conventions_and_tuples_name_the_same_ones() -> None:
    assert len(ALL_AXES) == 24
    assert len(set(T._AXES2TUPLE.values())) == 24
    for axes, code in T._AXES2TUPLE.items():
        assert np.allclose(T.euler_matrix(0.1, 0.2, 0.3, code), T.euler_matrix(0.1, 0.2, 0.3, axes))


@pytest.mark.parametrize("axes", ALL_AXES)
def test_euler_matrix_and_quaternion_match_scipy(axes: str) -> None:
    for angles in ANGLES:
        expected = Rotation.from_euler(scipy_sequence(axes), angles)
        assert np.allclose(T.euler_matrix(*angles, axes=axes)[:3, :3], expected.as_matrix())
        q = T.quaternion_from_euler(*angles, axes=axes)
        assert abs(abs(float(np.dot(q, expected.as_quat()))) - 1.0) < 1e-12  # same up to sign


@pytest.mark.parametrize("axes", ALL_AXES)
def test_euler_from_matrix_gives_scipys_angles(axes: str) -> None:
    proper_odd = axes[1] == axes[3] and T._AXES2TUPLE[axes][1] == 1
    for angles in ANGLES:
        matrix = T.euler_matrix(*angles, axes=axes)
        ours = np.array(T.euler_from_matrix(matrix, axes))
        theirs = Rotation.from_matrix(matrix[:3, :3]).as_euler(scipy_sequence(axes))
        if proper_odd:
            # ROS's module gives the middle angle in [-pi, 0] here, scipy in [0, pi]: the same
            # rotation as (a - pi, -b, c + pi).
            assert -math.pi - 1e-12 <= ours[1] <= 1e-12
            theirs = theirs + np.array([-math.pi, 0.0, math.pi])
            theirs[1] = -theirs[1]
        wrapped = (ours - theirs + math.pi) % (2 * math.pi) - math.pi
        assert np.allclose(wrapped, 0.0, atol=1e-9), (axes, ours, theirs)
        quaternion = T.quaternion_from_euler(*angles, axes=axes)
        assert np.allclose(T.euler_from_quaternion(quaternion, axes), ours)


@pytest.mark.parametrize("axes", ALL_AXES)
def test_gimbal_lock_round_trips_and_zeroes_the_angle_ros_zeroes(axes: str) -> None:
    middle = (math.pi / 2, -math.pi / 2) if axes[1] != axes[3] else (0.0, math.pi)
    for b in middle:
        matrix = T.euler_matrix(0.4, b, -1.1, axes)
        angles = T.euler_from_matrix(matrix, axes)
        assert np.allclose(T.euler_matrix(*angles, axes=axes), matrix)
        zeroed = 2 if axes[0] == "s" else 0  # the angle applied last about the static axes
        assert angles[zeroed] == 0.0


def test_known_values_from_the_ros_module_documentation() -> None:
    assert np.allclose(
        T.quaternion_from_euler(1, 2, 3, "ryxz"), [0.310622, -0.718287, 0.444435, 0.435953]
    )
    assert np.allclose(np.sum(T.euler_matrix(1, 2, 3, "syxz")[0]), -1.34786452)
    assert np.allclose(np.sum(T.euler_matrix(1, 2, 3, (0, 1, 0, 1))[0]), -0.383436184)
    assert np.allclose(T.euler_from_quaternion([0.06146124, 0, 0, 0.99810947]), [0.123, 0, 0])
    assert np.allclose(T.quaternion_about_axis(0.123, (1, 0, 0)), [0.06146124, 0, 0, 0.99810947])
    q = T.quaternion_from_matrix(T.rotation_matrix(0.123, (1, 2, 3)))
    assert np.allclose(q, [0.0164262, 0.0328524, 0.0492786, 0.9981095])
    assert np.allclose(T.quaternion_multiply([1, -2, 3, 4], [-5, 6, 7, 8]), [-44, -14, 48, 28])
    assert np.allclose(
        T.orthogonalization_matrix([9.8, 12.0, 15.5], [87.2, 80.7, 69.7]).sum(), 43.063229
    )


def test_a_yaw_from_odometry_the_way_courses_read_it() -> None:
    x, y, z, w = Rotation.from_euler("z", 2.5).as_quat()
    roll, pitch, yaw = T.euler_from_quaternion([x, y, z, w])
    assert (roll, pitch) == pytest.approx((0.0, 0.0), abs=1e-12)
    assert yaw == pytest.approx(2.5)
    assert np.allclose(T.quaternion_from_euler(0, 0, 2.5), [x, y, z, w])


def test_quaternion_algebra_matches_scipy() -> None:
    for _ in range(20):
        a, b = T.random_quaternion(), T.random_quaternion()
        assert T.vector_norm(a) == pytest.approx(1.0)
        product = Rotation.from_quat(a) * Rotation.from_quat(b)
        assert abs(abs(float(np.dot(T.quaternion_multiply(a, b), product.as_quat()))) - 1) < 1e-12
        assert np.allclose(T.quaternion_multiply(a, T.quaternion_inverse(a)), [0, 0, 0, 1])
        assert np.allclose(T.quaternion_conjugate(a), [-a[0], -a[1], -a[2], a[3]])
        assert np.allclose(T.quaternion_matrix(a)[:3, :3], Rotation.from_quat(a).as_matrix())
        back = T.quaternion_from_matrix(T.quaternion_matrix(a))
        assert abs(abs(float(np.dot(back, a))) - 1.0) < 1e-12


def test_slerp_ends_midpoint_and_short_way() -> None:
    q0, q1 = T.quaternion_from_euler(0, 0, 0.2), T.quaternion_from_euler(0, 0, 1.0)
    assert np.allclose(T.quaternion_slerp(q0, q1, 0.0), q0)
    assert np.allclose(T.quaternion_slerp(q0, q1, 1.0), q1)
    assert T.euler_from_quaternion(T.quaternion_slerp(q0, q1, 0.25))[2] == pytest.approx(0.4)
    # -q1 is the same rotation; the shortest path still ends up halfway at yaw 0.6.
    assert T.euler_from_quaternion(T.quaternion_slerp(q0, -q1, 0.5))[2] == pytest.approx(0.6)


def test_decompose_inverts_compose() -> None:
    for _ in range(20):
        scale = RNG.random(3) + 0.2
        shear, angles = RNG.random(3) - 0.5, (RNG.random(3) - 0.5) * 2
        translate, perspective = RNG.random(3) - 0.5, RNG.random(4) - 0.5
        matrix = T.compose_matrix(scale, shear, angles, translate, perspective)
        parts = T.decompose_matrix(matrix)
        assert T.is_same_transform(T.compose_matrix(*parts), matrix)
        # Without perspective nothing is rescaled, so every part comes back as given.
        scale_back, shear_back, angles_back, translate_back, perspective_back = T.decompose_matrix(
            T.compose_matrix(scale, shear, angles, translate)
        )
        assert np.allclose(scale_back, scale) and np.allclose(shear_back, shear)
        assert np.allclose(angles_back, angles) and np.allclose(translate_back, translate)
        assert np.allclose(perspective_back, [0, 0, 0, 1])


def test_affine_transforms_recover_their_parameters() -> None:
    for _ in range(20):
        point, normal = RNG.random(3) - 0.5, RNG.random(3) - 0.5
        direction, eye = RNG.random(3) - 0.5, RNG.random(3) - 0.5
        factor, angle = RNG.random() * 3 + 0.1, (RNG.random() - 0.5) * 2
        cases = [
            (T.reflection_matrix(point, normal), T.reflection_from_matrix, T.reflection_matrix),
            (T.scale_matrix(factor, point), T.scale_from_matrix, T.scale_matrix),
            (T.scale_matrix(factor, point, direction), T.scale_from_matrix, T.scale_matrix),
            (T.rotation_matrix(angle, direction, point), T.rotation_from_matrix, T.rotation_matrix),
            (T.projection_matrix(point, normal), T.projection_from_matrix, T.projection_matrix),
            (
                T.projection_matrix(point, normal, direction),
                T.projection_from_matrix,
                T.projection_matrix,
            ),
            (
                T.shear_matrix(angle, direction, point, np.cross(direction, normal)),
                T.shear_from_matrix,
                T.shear_matrix,
            ),
        ]
        for matrix, analyse, build in cases:
            assert T.is_same_transform(build(*analyse(matrix)), matrix)
        perspective = T.projection_matrix(point, normal, perspective=eye)
        pseudo = T.projection_matrix(point, normal, perspective=eye, pseudo=True)
        assert T.is_same_transform(perspective, T.projection_matrix(point, normal) @ pseudo)
        rebuilt = T.projection_matrix(*T.projection_from_matrix(pseudo, pseudo=True))
        assert T.is_same_transform(rebuilt, pseudo)


def test_superimposition_finds_the_rigid_motion_both_ways() -> None:
    motion = T.concatenate_matrices(
        T.translation_matrix([0.3, -0.2, 1.0]), T.random_rotation_matrix(), T.scale_matrix(1.7)
    )
    points = (RNG.random((4, 30)) - 0.5) * 10
    points[3] = 1.0
    for usesvd in (True, False):
        found = T.superimposition_matrix(points, motion @ points, scaling=True, usesvd=usesvd)
        assert np.allclose(found, motion)


def test_clip_matrix_maps_the_box_corners_to_minus_and_plus_one() -> None:
    bounds = (0.1, 0.5, 0.2, 0.9, 0.3, 1.7)
    box = T.clip_matrix(*bounds)
    assert np.allclose(box @ [0.1, 0.2, 0.3, 1.0], [-1, -1, -1, 1])
    assert np.allclose(box @ [0.5, 0.9, 1.7, 1.0], [1, 1, 1, 1])
    frustum = T.clip_matrix(*bounds, perspective=True)
    corner = frustum @ [0.1, 0.2, 0.3, 1.0]
    assert np.allclose(corner / corner[3], [-1, -1, -1, 1])
    with pytest.raises(ValueError, match="left < right"):
        T.clip_matrix(1, 0, 0, 1, 0, 1)


def test_arcball_turns_with_a_drag() -> None:
    ball = T.Arcball()
    ball.place([320, 320], 320)
    ball.down([320, 320])
    ball.drag([420, 320])  # rightwards: a turn about the window's vertical (y) axis
    turn = ball.matrix()
    assert not np.allclose(turn, np.identity(4))
    angle, axis, _ = T.rotation_from_matrix(turn)
    assert abs(axis[1]) == pytest.approx(1.0) and angle != 0.0


def test_matrix_helpers() -> None:
    assert np.array_equal(T.identity_matrix(), np.identity(4))
    move = T.translation_matrix([1, 2, 3])
    assert np.allclose(T.translation_from_matrix(move), [1, 2, 3])
    assert np.allclose(T.concatenate_matrices(move, T.inverse_matrix(move)), np.identity(4))
    assert T.unit_vector([3.0, 4.0]) == pytest.approx([0.6, 0.8])
    assert T.vector_norm([3.0, 4.0]) == 5.0
    rows = T.vector_norm([[3.0, 4.0], [6.0, 8.0]], axis=1)
    assert np.allclose(rows, [5.0, 10.0])
    assert not T.is_same_transform(move, T.identity_matrix())


def test_a_message_instead_of_a_list_gets_a_sentence() -> None:
    with pytest.raises(TypeError, match=r"\[q\.x, q\.y, q\.z, q\.w\]"):
        T.euler_from_quaternion(Quaternion(0, 0, 0, 1))
    with pytest.raises(ValueError, match="4 numbers"):
        T.euler_from_quaternion([0, 0, 1])


def test_unknown_axes_get_a_sentence() -> None:
    with pytest.raises(ValueError, match="24 conventions"):
        T.quaternion_from_euler(0, 0, 1, "xyz")
    with pytest.raises(ValueError, match="24 conventions"):
        T.euler_from_matrix(np.identity(4), (3, 0, 0, 0))


def test_star_import_gives_the_public_functions() -> None:
    install_ros_compat()  # a ROS 2 node run in this process before switched the layers over
    namespace: dict[str, object] = {}
    exec("from tf.transformations import *", namespace)
    for name in ("euler_from_quaternion", "quaternion_from_euler", "quaternion_multiply",
                 "decompose_matrix", "Arcball"):  # fmt: skip
        assert callable(namespace[name])
    assert "_EPS" not in namespace and "np" not in namespace
