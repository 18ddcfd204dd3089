"""ROS1 message types: the one definition used by the simulator, student code, rosserial and
recordings.

Each class is generated from its ``.msg`` definition text (see ``_core.py``)::

    from sandbox.msgs import geometry_msgs
    cmd = geometry_msgs.Twist(linear=geometry_msgs.Vector3(x=0.2))
    data = cmd.serialize()
    assert geometry_msgs.Twist.deserialize(data) == cmd
"""

from __future__ import annotations

from . import geometry_msgs, nav_msgs, sensor_msgs, std_msgs, tf2_msgs
from ._core import (
    MESSAGE_TYPES,
    DeserializationError,
    Message,
    SerializationError,
    UnknownMessageTypeError,
    get_message_class,
)
from ._time import Duration, Time

__all__ = [
    "MESSAGE_TYPES",
    "DeserializationError",
    "Duration",
    "Message",
    "SerializationError",
    "Time",
    "UnknownMessageTypeError",
    "geometry_msgs",
    "get_message_class",
    "nav_msgs",
    "sensor_msgs",
    "std_msgs",
    "tf2_msgs",
]
