"""rosserial host (what ``rosserial_python serial_node.py tcp`` does) for robots running ros_lib.

- ``frames``: the wire format, and a parser that survives any input (pure).
- ``session``: one connection's protocol state machine (pure, sans-IO); ``events``: what it
  reports.
- ``server``: the TCP server, one session per robot, callbacks to the rest of RoboDojo.
- ``admission``: who gets a session (ros_lib has no authentication), back-off of refused peers.
- ``limits``: every limit in one table. ``messages``: rosserial_msgs TopicInfo and Log.
- ``link``: a connected robot as a run's `RobotLink` (imported from there, not here: it needs the
  hardware backend, which this package does not).

Protocol facts and their sources are in each module's docstring and shared/notes/protocols.md.
"""

from server.hardware.rosserial.admission import Refusal
from server.hardware.rosserial.events import Direction, RobotTopic
from server.hardware.rosserial.frames import DropReason, Frame, FrameParser, TopicId, encode_frame
from server.hardware.rosserial.limits import DEFAULT_LIMITS, RosserialLimits
from server.hardware.rosserial.messages import LogLevel
from server.hardware.rosserial.server import (
    DEFAULT_PORT,
    RobotConnection,
    RosserialHandler,
    RosserialServer,
)
from server.hardware.rosserial.session import (
    RobotDisconnected,
    RosserialSession,
    SessionError,
    SessionState,
    TopicError,
)

__all__ = [
    "DEFAULT_LIMITS",
    "DEFAULT_PORT",
    "Direction",
    "DropReason",
    "Frame",
    "FrameParser",
    "LogLevel",
    "Refusal",
    "RobotConnection",
    "RobotDisconnected",
    "RobotTopic",
    "RosserialHandler",
    "RosserialLimits",
    "RosserialServer",
    "RosserialSession",
    "SessionError",
    "SessionState",
    "TopicError",
    "TopicId",
    "encode_frame",
]
