"""The matrix and quaternion helpers of C. Gohlke's transformations.py, which ROS 1 ships as
`tf.transformations` and ROS 2 as the `tf_transformations` package: 4x4 homogeneous transforms,
Euler angles and quaternions. Quaternions are [x, y, z, w]; Euler conventions are the 24 axes
strings such as 'sxyz' (the default: static x, y, z, i.e. roll, pitch, yaw) or their 4-tuples;
angles are in radians; results are numpy arrays.

One implementation for both dialects: sandbox/ros_compat/tf/transformations.py (ROS 1) and
sandbox/ros_compat2/tf_transformations (ROS 2, which returns some quaternions as tuples) import
it. Written here from the published math (see the sources in _rotations.py and _affine.py).
"""

from ._affine import (
    clip_matrix,
    compose_matrix,
    decompose_matrix,
    orthogonalization_matrix,
    projection_from_matrix,
    projection_matrix,
    reflection_from_matrix,
    reflection_matrix,
    scale_from_matrix,
    scale_matrix,
    shear_from_matrix,
    shear_matrix,
    superimposition_matrix,
)
from ._arcball import (
    Arcball,
    arcball_constrain_to_axis,
    arcball_map_to_sphere,
    arcball_nearest_axis,
)
from ._rotations import (
    _AXES2TUPLE,
    _NEXT_AXIS,
    _TUPLE2AXES,
    euler_from_matrix,
    euler_from_quaternion,
    euler_matrix,
    quaternion_about_axis,
    quaternion_conjugate,
    quaternion_from_euler,
    quaternion_from_matrix,
    quaternion_inverse,
    quaternion_matrix,
    quaternion_multiply,
    quaternion_slerp,
    random_quaternion,
    random_rotation_matrix,
    rotation_from_matrix,
    rotation_matrix,
)
from ._vectors import EPS as _EPS
from ._vectors import (
    concatenate_matrices,
    identity_matrix,
    inverse_matrix,
    is_same_transform,
    random_vector,
    translation_from_matrix,
    translation_matrix,
    unit_vector,
    vector_norm,
)

__all__ = [
    "Arcball",
    "arcball_constrain_to_axis",
    "arcball_map_to_sphere",
    "arcball_nearest_axis",
    "clip_matrix",
    "compose_matrix",
    "concatenate_matrices",
    "decompose_matrix",
    "euler_from_matrix",
    "euler_from_quaternion",
    "euler_matrix",
    "identity_matrix",
    "inverse_matrix",
    "is_same_transform",
    "orthogonalization_matrix",
    "projection_from_matrix",
    "projection_matrix",
    "quaternion_about_axis",
    "quaternion_conjugate",
    "quaternion_from_euler",
    "quaternion_from_matrix",
    "quaternion_inverse",
    "quaternion_matrix",
    "quaternion_multiply",
    "quaternion_slerp",
    "random_quaternion",
    "random_rotation_matrix",
    "random_vector",
    "reflection_from_matrix",
    "reflection_matrix",
    "rotation_from_matrix",
    "rotation_matrix",
    "scale_from_matrix",
    "scale_matrix",
    "shear_from_matrix",
    "shear_matrix",
    "superimposition_matrix",
    "translation_from_matrix",
    "translation_matrix",
    "unit_vector",
    "vector_norm",
]
_PRIVATE_NAMES_SCRIPTS_READ = (_AXES2TUPLE, _TUPLE2AXES, _NEXT_AXIS, _EPS)
