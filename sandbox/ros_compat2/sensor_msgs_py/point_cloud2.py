"""sensor_msgs_py.point_cloud2: sensor_msgs/msg/PointCloud2 <-> numpy, with the functions and
behaviour of ros2/common_interfaces sensor_msgs_py/point_cloud2.py.

    from sensor_msgs_py import point_cloud2
    for x, y, z in point_cloud2.read_points(cloud, field_names=("x", "y", "z"), skip_nans=True):
        ...
    cloud = point_cloud2.create_cloud_xyz32(header, [[1.0, 0.0, 0.2], [1.1, 0.1, 0.2]])

A cloud's `fields` describe one point's bytes (name, offset, datatype, count); here they become
a numpy structured dtype whose itemsize is the cloud's point_step, so read_points is a view of
`data`, not a copy. A field with count > 1 becomes `name_0`, `name_1`, ...; an unnamed one
`unnamed_field_<i>`. Mistakes fail with AssertionError, as in ROS 2, in a sentence.
"""

from __future__ import annotations

import array
import sys
from collections import namedtuple
from collections.abc import Iterable
from typing import Any

import numpy as np
from numpy.lib.recfunctions import structured_to_unstructured, unstructured_to_structured

from sandbox.msgs import get_message_class

# sensor_msgs/msg/PointField datatype constants -> numpy types (the .msg file's values).
_DATATYPES = {
    1: np.dtype(np.int8),  # INT8
    2: np.dtype(np.uint8),  # UINT8
    3: np.dtype(np.int16),  # INT16
    4: np.dtype(np.uint16),  # UINT16
    5: np.dtype(np.int32),  # INT32
    6: np.dtype(np.uint32),  # UINT32
    7: np.dtype(np.float32),  # FLOAT32
    8: np.dtype(np.float64),  # FLOAT64
}
DUMMY_FIELD_PREFIX = "unnamed_field"
_CLOUD_TYPE = "sensor_msgs/msg/PointCloud2"


def _check_cloud(cloud: Any) -> None:
    assert getattr(cloud, "_type", None) == _CLOUD_TYPE, (
        f"Cloud is not a sensor_msgs.msg.PointCloud2 (got {type(cloud).__name__}); pass the "
        "message your subscription callback received"
    )


def dtype_from_fields(fields: Iterable[Any], point_step: int | None = None) -> np.dtype:
    """The numpy structured dtype of one point described by PointField messages."""
    names: list[str] = []
    offsets: list[int] = []
    formats: list[str] = []
    for index, field in enumerate(fields):
        datatype = _DATATYPES.get(field.datatype)
        assert datatype is not None, (
            f"PointField '{field.name}' has datatype {field.datatype}; the datatypes are "
            "PointField.INT8 (1) to PointField.FLOAT64 (8)"
        )
        assert field.count > 0, f"Can't process fields with count = 0 ('{field.name}')."
        name = field.name or f"{DUMMY_FIELD_PREFIX}_{index}"
        for element in range(field.count):
            element_name = f"{name}_{element}" if field.count > 1 else name
            assert element_name not in names, (
                f"Duplicate field names are not allowed! ('{element_name}' appears twice)"
            )
            names.append(element_name)
            offsets.append(field.offset + element * datatype.itemsize)
            formats.append(datatype.str)
    spec: dict[str, Any] = {"names": names, "formats": formats, "offsets": offsets}
    if point_step is not None:
        spec["itemsize"] = point_step
    return np.dtype(spec)


def read_points(
    cloud: Any,
    field_names: Iterable[str] | None = None,
    skip_nans: bool = False,
    uvs: Iterable[int] | None = None,
    reshape_organized_cloud: bool = False,
) -> np.ndarray:
    """The cloud's points as a numpy structured array (one row per point, a column per field);
    only `field_names` if given; without points holding a NaN if `skip_nans` (and the cloud is
    not dense); only the points at indices `uvs`; height x width if `reshape_organized_cloud`."""
    _check_cloud(cloud)
    points = np.ndarray(
        shape=(cloud.width * cloud.height,),
        dtype=dtype_from_fields(cloud.fields, point_step=cloud.point_step),
        buffer=memoryview(cloud.data),
    )
    if field_names is not None:
        wanted = list(field_names)
        missing = [name for name in wanted if name not in points.dtype.names]
        assert not missing, (
            f"Requests field is not in the fields of the PointCloud! ({', '.join(missing)} not "
            f"in {', '.join(points.dtype.names)})"
        )
        points = points[wanted]
    if (sys.byteorder != "little") != bool(cloud.is_bigendian):
        points = points.byteswap()
    if skip_nans and not cloud.is_dense:
        keep = np.ones(len(points), dtype=bool)
        for name in points.dtype.names:
            keep &= ~np.isnan(points[name])
        points = points[keep]
    if uvs is not None:
        points = points[uvs if isinstance(uvs, np.ndarray) else np.fromiter(uvs, int)]
    if reshape_organized_cloud and cloud.height > 1:
        points = points.reshape(cloud.width, cloud.height)
    return points


def read_points_numpy(
    cloud: Any,
    field_names: Iterable[str] | None = None,
    skip_nans: bool = False,
    uvs: Iterable[int] | None = None,
    reshape_organized_cloud: bool = False,
) -> np.ndarray:
    """read_points as a plain 2D numpy array (points x fields); the fields must share a type."""
    wanted = None if field_names is None else list(field_names)
    chosen = [f for f in cloud.fields if wanted is None or f.name in wanted]
    assert all(f.datatype == chosen[0].datatype for f in chosen[1:]), (
        "All fields need to have the same datatype. Use `read_points()` otherwise."
    )
    structured = read_points(cloud, wanted, skip_nans, uvs, reshape_organized_cloud)
    return structured_to_unstructured(structured)


def read_points_list(
    cloud: Any,
    field_names: Iterable[str] | None = None,
    skip_nans: bool = False,
    uvs: Iterable[int] | None = None,
) -> list[Any]:
    """read_points as a list of namedtuples `Point(x=..., y=..., ...)`."""
    _check_cloud(cloud)
    names = [f.name for f in cloud.fields] if field_names is None else list(field_names)
    point_type = namedtuple("Point", names)
    return [point_type._make(row) for row in read_points(cloud, names, skip_nans, uvs)]


def create_cloud(
    header: Any, fields: Iterable[Any], points: Any, point_step: int | None = None
) -> Any:
    """A sensor_msgs/msg/PointCloud2 of `points` (a list of per-point sequences in the order
    of `fields`, or a numpy array: plain 2D or structured) laid out as `fields` say."""
    fields = list(fields)
    dtype = dtype_from_fields(fields, point_step)
    if isinstance(points, np.ndarray):
        if points.dtype.names is None:
            assert all(f.datatype == fields[0].datatype for f in fields[1:]), (
                "All fields need to have the same datatype. Pass a structured NumPy array with "
                "multiple dtypes otherwise."
            )
            points = unstructured_to_structured(points, dtype=dtype)
        else:
            assert points.dtype == dtype, (
                "PointFields and structured NumPy array dtype do not match for all fields! "
                "Check their field order, names and types."
            )
    else:
        points = np.array([tuple(point) for point in points], dtype=dtype)
    assert points.ndim <= 2, (
        "Too many dimensions for organized cloud! Points can only be organized in max. two "
        "dimensional space"
    )
    width = points.shape[0]
    height = points.shape[1] if points.ndim == 2 else 1
    cloud_class = get_message_class(_CLOUD_TYPE)
    cloud = cloud_class(
        header=header,
        height=height,
        width=width,
        is_dense=False,
        is_bigendian=sys.byteorder != "little",
        fields=fields,
        point_step=points.dtype.itemsize,
        row_step=points.dtype.itemsize * width,
    )
    data = array.array("B")
    data.frombytes(np.ascontiguousarray(points).tobytes())
    cloud.data = data
    return cloud


def create_cloud_xyz32(header: Any, points: Any) -> Any:
    """A PointCloud2 with float32 fields x, y, z (offsets 0, 4, 8)."""
    field_class = get_message_class("sensor_msgs/msg/PointField")
    float32 = 7  # PointField.FLOAT32
    fields = [
        field_class(name=name, offset=4 * index, datatype=float32, count=1)
        for index, name in enumerate("xyz")
    ]
    return create_cloud(header, fields, points)
