"""sensor_msgs_py.point_cloud2 with ROS 2 PointCloud2 messages: the layouts ROS 2's module
builds and reads (fields, offsets, point_step), NaN skipping, organized clouds, and sentences
for the mistakes."""

from __future__ import annotations

import importlib
import math

import numpy as np
import pytest

from sandbox.msgs import get_message_class
from tests.ros2libs.loading import load_ros2_package

load_ros2_package("sensor_msgs_py")
point_cloud2 = importlib.import_module("sensor_msgs_py.point_cloud2")


Header = get_message_class("std_msgs/msg/Header")
PointCloud2 = get_message_class("sensor_msgs/msg/PointCloud2")
PointField = get_message_class("sensor_msgs/msg/PointField")


def test_create_cloud_xyz32_lays_points_out_as_ros2_does() -> None:
    module = point_cloud2
    points = [[1.0, 2.0, 3.0], [-0.5, 0.25, 0.0], [4.0, 5.0, 6.0]]
    cloud = module.create_cloud_xyz32(Header(frame_id="base_scan"), points)
    assert isinstance(cloud, PointCloud2)
    assert (cloud.height, cloud.width, cloud.point_step, cloud.row_step) == (1, 3, 12, 36)
    assert [(f.name, f.offset, f.datatype, f.count) for f in cloud.fields] == [
        ("x", 0, PointField.FLOAT32, 1),
        ("y", 4, PointField.FLOAT32, 1),
        ("z", 8, PointField.FLOAT32, 1),
    ]
    assert bytes(cloud.data) == np.array(points, dtype="<f4").tobytes()
    back = PointCloud2.deserialize(cloud.serialize())  # survives CDR
    assert module.read_points_list(back) == [tuple(p) for p in points]
    assert module.read_points_list(back)[1].y == 0.25


def test_read_points_selects_fields_skips_nans_and_indexes() -> None:
    module = point_cloud2
    fields = [
        PointField(name="x", offset=0, datatype=PointField.FLOAT32, count=1),
        PointField(name="y", offset=4, datatype=PointField.FLOAT32, count=1),
        PointField(name="intensity", offset=8, datatype=PointField.UINT16, count=1),
    ]
    rows = [(1.0, 1.5, 7), (math.nan, 2.0, 8), (3.0, 3.5, 9)]
    cloud = module.create_cloud(Header(), fields, rows)
    assert cloud.point_step == 10
    everything = module.read_points(cloud)
    assert everything.dtype.names == ("x", "y", "intensity") and len(everything) == 3
    kept = module.read_points(cloud, field_names=("x", "intensity"), skip_nans=True)
    assert kept.tolist() == [(1.0, 7), (3.0, 9)]
    assert module.read_points(cloud, uvs=[2])["intensity"].tolist() == [9]
    xy = module.read_points_numpy(cloud, field_names=["x", "y"], skip_nans=True)
    assert xy.shape == (2, 2) and xy[1].tolist() == [3.0, 3.5]


def test_numpy_input_and_organized_clouds() -> None:
    module = point_cloud2
    grid = np.arange(24, dtype=np.float32).reshape(4, 2, 3)  # width 4, height 2, xyz
    fields = [PointField(name=n, offset=4 * i, datatype=PointField.FLOAT32, count=1)
              for i, n in enumerate("xyz")]  # fmt: skip
    cloud = module.create_cloud(Header(), fields, grid)
    assert (cloud.width, cloud.height) == (4, 2)
    organized = module.read_points(cloud, reshape_organized_cloud=True)
    assert organized.shape == (4, 2) and organized[3, 1]["z"] == 23.0


def test_count_above_one_becomes_numbered_columns() -> None:
    module = point_cloud2
    fields = [PointField(name="rgb", offset=0, datatype=PointField.UINT8, count=3)]
    cloud = module.create_cloud(Header(), fields, [(255, 128, 0)])
    assert module.read_points(cloud).dtype.names == ("rgb_0", "rgb_1", "rgb_2")


def test_mistakes_get_sentences() -> None:
    module = point_cloud2
    cloud = module.create_cloud_xyz32(Header(), [[0.0, 0.0, 0.0]])
    with pytest.raises(AssertionError, match=r"not in the fields.*\(w not in x, y, z\)"):
        module.read_points(cloud, field_names=["x", "w"])
    with pytest.raises(AssertionError, match=r"not a sensor_msgs\.msg\.PointCloud2"):
        module.read_points([[0.0, 0.0, 0.0]])
    bad = [PointField(name="x", offset=0, datatype=42, count=1)]
    with pytest.raises(AssertionError, match="datatype 42"):
        module.create_cloud(Header(), bad, [(1,)])
