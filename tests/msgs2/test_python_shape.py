"""ROS 2 message classes behave as rosidl_generator_py's (ros2/rosidl_python, _msg.py.em)."""

from __future__ import annotations

import copy
import pickle
from array import array

import numpy
import pytest

from sandbox.msgs2 import SerializationError, UnknownMessageTypeError, get_message_class
from sandbox.msgs2._slot_types import BasicType, NamespacedType, UnboundedSequence

Int32 = get_message_class("std_msgs/msg/Int32")
Twist = get_message_class("geometry_msgs/msg/Twist")
Vector3 = get_message_class("geometry_msgs/msg/Vector3")
LaserScan = get_message_class("sensor_msgs/msg/LaserScan")
Odometry = get_message_class("nav_msgs/msg/Odometry")


def test_repr_type_name_and_module_follow_rosidl() -> None:
    assert repr(Int32(data=3)) == "std_msgs.msg.Int32(data=3)"
    assert Int32._type == "std_msgs/msg/Int32"
    assert Int32.__module__ == "std_msgs.msg._int32"
    scan = LaserScan(ranges=[1.5, 2.0])
    assert "ranges=[1.5, 2.0], intensities=[]" in repr(scan)


def test_the_constructor_takes_keywords_only_and_warns_of_unknown_ones() -> None:
    with pytest.raises(TypeError):
        Int32(3)  # type: ignore[misc]
    # Jazzy ignores an unknown keyword unless the checks are on; we say so in the log.
    with pytest.warns(UserWarning, match="ignored unknown constructor arguments: dta"):
        assert Int32(dta=3).data == 0
    with pytest.raises(AssertionError, match="Invalid arguments passed to constructor: dta"):
        Int32(dta=3, check_fields=True)


def test_defaults_come_from_the_definition() -> None:
    Quaternion = get_message_class("geometry_msgs/msg/Quaternion")
    assert (Quaternion().x, Quaternion().w) == (0.0, 1.0)
    assert Quaternion.W__DEFAULT == 1.0
    scan = LaserScan()
    assert isinstance(scan.ranges, array) and scan.ranges.typecode == "f"
    odom = Odometry()
    assert isinstance(odom.pose.covariance, numpy.ndarray)
    assert odom.pose.covariance.dtype == numpy.float64 and odom.pose.covariance.shape == (36,)
    assert odom.header.frame_id == "" and odom.header.stamp.nanosec == 0


def test_setters_check_types_and_ranges_with_assertion_errors_when_asked() -> None:
    Vector3 = get_message_class("geometry_msgs/msg/Vector3")
    vector = Vector3(check_fields=True)
    with pytest.raises(AssertionError, match="'x' field must be a double"):
        vector.x = 1  # an int into a float64 field, as rosidl refuses it when checking
    with pytest.raises(AssertionError, match="sub message of type 'Vector3'"):
        Twist(check_fields=True).linear = 5
    UInt8 = get_message_class("std_msgs/msg/UInt8")
    with pytest.raises(AssertionError, match=r"\[0, 255\]"):
        UInt8(data=256, check_fields=True)
    with pytest.raises(AssertionError, match="each value"):
        LaserScan(ranges=["a"], check_fields=True)
    vector.x = 0.5
    assert vector.x == 0.5


def test_unchecked_fields_take_what_jazzy_takes_and_fail_at_serialize() -> None:
    twist = Twist()
    twist.linear.x = 1  # Jazzy (ROS_PYTHON_CHECK_FIELDS unset) accepts an int here
    assert Twist.deserialize(twist.serialize()).linear.x == 1.0
    UInt8 = get_message_class("std_msgs/msg/UInt8")
    with pytest.raises(SerializationError, match=r"UInt8.data: .*\[0, 255\], got 256"):
        UInt8(data=256).serialize()
    odom = Odometry()
    with pytest.raises(AssertionError, match="exactly 36 values"):
        odom.pose.covariance = [0.0] * 35  # a fixed array's numpy conversion checks always


def test_sequences_become_array_array_and_fixed_arrays_numpy() -> None:
    scan = LaserScan()
    scan.ranges = [1.0, 2.0]
    assert scan.ranges == array("f", [1.0, 2.0])
    scan.ranges = numpy.ones(3, dtype=numpy.float32).tolist()
    assert scan.ranges.typecode == "f"
    odom = Odometry()
    odom.pose.covariance = [1.0] * 36
    assert isinstance(odom.pose.covariance, numpy.ndarray)
    back = Odometry.deserialize(odom.serialize())
    assert isinstance(back.pose.covariance, numpy.ndarray) and back.pose.covariance[5] == 1.0
    back.pose.covariance[0] = 2.0  # writable, as rosidl's are


def test_constants_are_class_attributes() -> None:
    Marker = get_message_class("visualization_msgs/msg/Marker")
    assert (Marker.ARROW, Marker.DELETEALL) == (0, 3)
    assert Marker().ARROW == 0
    marker = Marker(type=Marker.SPHERE)
    assert marker.type == 2 and Marker._type == "visualization_msgs/msg/Marker"
    assert Marker.deserialize(marker.serialize()).type == 2


def test_equality_field_by_field() -> None:
    assert Twist() == Twist()
    assert Twist(linear=Vector3(x=1.0)) != Twist()
    assert Int32(data=1) != 1
    a, b = Odometry(), Odometry()
    b.pose.covariance[3] = 1.0
    assert a != b
    with pytest.raises(TypeError):
        hash(Int32())


def test_fields_and_slot_types() -> None:
    assert LaserScan.get_fields_and_field_types()["ranges"] == "sequence<float>"
    assert LaserScan.get_fields_and_field_types()["header"] == "std_msgs/Header"
    assert Odometry.get_fields_and_field_types()["child_frame_id"] == "string"
    PoseWithCovariance = get_message_class("geometry_msgs/msg/PoseWithCovariance")
    assert PoseWithCovariance.get_fields_and_field_types()["covariance"] == "double[36]"
    assert LaserScan.SLOT_TYPES[0] == NamespacedType(["std_msgs", "msg"], "Header")
    assert LaserScan.SLOT_TYPES[1] == BasicType("float")
    assert LaserScan.SLOT_TYPES[-1] == UnboundedSequence(BasicType("float"))
    assert "_ranges" in LaserScan.__slots__


def test_copy_deepcopy_and_pickle() -> None:
    odom = Odometry(child_frame_id="base_footprint")
    odom.pose.pose.position.x = 1.25
    for clone in (copy.deepcopy(odom), pickle.loads(pickle.dumps(odom))):
        assert clone == odom and clone is not odom
        assert clone.pose is not odom.pose
    shallow = copy.copy(odom)
    assert shallow == odom and shallow.pose is odom.pose


def test_unknown_types_get_a_sentence() -> None:
    with pytest.raises(UnknownMessageTypeError, match="did you mean std_msgs/msg/String"):
        get_message_class("std_msgs/msg/Strin")
    with pytest.raises(UnknownMessageTypeError, match="no ROS 2 package 'foo_msgs'"):
        get_message_class("foo_msgs/msg/Bar")
    with pytest.raises(UnknownMessageTypeError, match="package/msg/Name"):
        get_message_class("std_msgs//Int32")
