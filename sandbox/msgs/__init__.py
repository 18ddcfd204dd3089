"""ROS1 message and service types: the one definition used by the simulator, student code,
rosserial and recordings.

Every message and service of the ROS 1 noetic packages std_msgs, geometry_msgs, sensor_msgs,
nav_msgs, visualization_msgs, actionlib_msgs, tf2_msgs and std_srvs, generated from their
``.msg`` definition text (see ``_core.py``; the table is ``_definitions.py``). A class is built
the first time it is used::

    from sandbox.msgs import geometry_msgs
    cmd = geometry_msgs.Twist(linear=geometry_msgs.Vector3(x=0.2))
    data = cmd.serialize()
    assert geometry_msgs.Twist.deserialize(data) == cmd
"""

from __future__ import annotations

from . import (
    actionlib_msgs,
    geometry_msgs,
    nav_msgs,
    sensor_msgs,
    std_msgs,
    std_srvs,
    tf2_msgs,
    visualization_msgs,
)
from ._core import (
    MESSAGE_TYPES,
    DeserializationError,
    Message,
    SerializationError,
    UnknownMessageTypeError,
    get_message_class,
)
from ._definitions import SERVICES as SERVICE_TYPES
from ._services import Service, UnknownServiceTypeError, get_service_class
from ._time import Duration, Time

__all__ = [
    "MESSAGE_TYPES",
    "SERVICE_TYPES",
    "DeserializationError",
    "Duration",
    "Message",
    "SerializationError",
    "Service",
    "Time",
    "UnknownMessageTypeError",
    "UnknownServiceTypeError",
    "actionlib_msgs",
    "geometry_msgs",
    "get_message_class",
    "get_service_class",
    "nav_msgs",
    "sensor_msgs",
    "std_msgs",
    "std_srvs",
    "tf2_msgs",
    "visualization_msgs",
]
