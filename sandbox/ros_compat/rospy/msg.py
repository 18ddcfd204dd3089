"""rospy.msg: AnyMsg, to subscribe to a topic without decoding its messages."""

from __future__ import annotations

from sandbox.runtime import ROSException


class AnyMsg:
    """A message of any type, kept as its serialized bytes in `_buff` (rospy.AnyMsg).

    Subscribe with it to a topic whose type the run knows (a robot topic or one a node
    publishes); the callback gets an AnyMsg whose `_buff` holds the ROS1 bytes and whose
    `_connection_header["type"]` names the type, as in rospy."""

    _type = "*"
    _md5sum = "*"
    _full_text = ""
    _has_header = False
    __slots__ = ("_buff", "_connection_header")

    def __init__(self, *args: object) -> None:
        if args:
            raise ROSException("AnyMsg does not accept arguments")
        self._buff: bytes | None = None
        self._connection_header: dict[str, str] = {}

    @classmethod
    def from_envelope(cls, data: bytes, type_name: str) -> AnyMsg:
        message = cls()
        message._buff = data
        message._connection_header = {"type": type_name}
        return message
