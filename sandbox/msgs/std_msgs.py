"""std_msgs: ROS1's basic message types (definitions as in ros/std_msgs, comments shortened)."""

from __future__ import annotations

from ._core import Message


class Header(Message):
    """Stamped data in a particular coordinate frame."""

    _type = "std_msgs/Header"
    _definition = """
# Standard metadata for higher-level stamped data types.
# sequence ID: consecutively increasing ID
uint32 seq
# Two-integer timestamp: stamp.sec seconds since epoch, stamp.nsec nanoseconds since stamp_secs
time stamp
# Frame this data is associated with
string frame_id
"""


class Bool(Message):
    _type = "std_msgs/Bool"
    _definition = "bool data"


class Int16(Message):
    _type = "std_msgs/Int16"
    _definition = "int16 data"


class Int32(Message):
    _type = "std_msgs/Int32"
    _definition = "int32 data"


class Float32(Message):
    _type = "std_msgs/Float32"
    _definition = "float32 data"


class Float64(Message):
    _type = "std_msgs/Float64"
    _definition = "float64 data"


class String(Message):
    _type = "std_msgs/String"
    _definition = "string data"


class Empty(Message):
    _type = "std_msgs/Empty"
    _definition = ""


class Time(Message):
    """A message wrapping one ``time`` value (rosserial's time-sync payload has this layout)."""

    _type = "std_msgs/Time"
    _definition = "time data"


class Duration(Message):
    _type = "std_msgs/Duration"
    _definition = "duration data"


class ColorRGBA(Message):
    _type = "std_msgs/ColorRGBA"
    _definition = """
float32 r
float32 g
float32 b
float32 a
"""


class MultiArrayDimension(Message):
    _type = "std_msgs/MultiArrayDimension"
    _definition = """
string label   # label of given dimension
uint32 size    # size of given dimension (in type units)
uint32 stride  # stride of given dimension
"""


class MultiArrayLayout(Message):
    _type = "std_msgs/MultiArrayLayout"
    _definition = """
# The multiarray declares a generic multi-dimensional array of a
# particular data type.  Dimensions are ordered from outer most
# to inner most.

MultiArrayDimension[] dim # Array of dimension properties
uint32 data_offset        # padding elements at front of data
"""


class Int32MultiArray(Message):
    _type = "std_msgs/Int32MultiArray"
    _definition = """
# Please look at the MultiArrayLayout message definition for
# documentation on all multiarrays.

MultiArrayLayout  layout        # specification of data layout
int32[]           data          # array of data
"""


class Float32MultiArray(Message):
    _type = "std_msgs/Float32MultiArray"
    _definition = """
# Please look at the MultiArrayLayout message definition for
# documentation on all multiarrays.

MultiArrayLayout  layout        # specification of data layout
float32[]         data          # array of data
"""
