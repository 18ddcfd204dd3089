"""What a rosserial session reports: one typed event per thing that happened (session.py).

``RosserialSession.receive_data()`` and ``poll()`` return lists of these; the server turns
them into handler calls (server.py).
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum

from sandbox.msgs import Message
from server.hardware.rosserial.messages import LogLevel


class Direction(StrEnum):
    PUBLISHES = "publishes"  # robot -> RoboDojo (sensor topics)
    SUBSCRIBES = "subscribes"  # RoboDojo -> robot (command topics)


@dataclass(frozen=True, slots=True)
class RobotTopic:
    """A topic the robot advertised and RoboDojo accepted (md5sum checked)."""

    name: str
    topic_id: int
    message_type: str
    direction: Direction
    buffer_size: int  # [bytes] the robot's buffer for this direction (ros_lib OUTPUT/INPUT_SIZE)
    message_class: type[Message]


@dataclass(frozen=True, slots=True)
class TopicRegistered:
    """The robot advertised a topic and RoboDojo set it up."""

    topic: RobotTopic


@dataclass(frozen=True, slots=True)
class TopicRefused:
    """The robot advertised a topic RoboDojo cannot carry (md5sum mismatch, unknown type)."""

    name: str
    message_type: str
    reason: str


@dataclass(frozen=True, slots=True)
class Ready:
    """Negotiation is over: the robot publishes and takes commands on its accepted topics."""


@dataclass(frozen=True, slots=True)
class MessageReceived:
    """A message the robot published on one of its accepted topics."""

    topic: str
    message: Message


@dataclass(frozen=True, slots=True)
class LogLine:
    """A line the robot logged (nh.loginfo() and friends)."""

    level: LogLevel
    text: str


@dataclass(frozen=True, slots=True)
class Problem:
    """Something the instructor should know (also kept in ``RosserialSession.problems``)."""

    text: str


@dataclass(frozen=True, slots=True)
class SyncLost:
    """No time request for the sync timeout; topics were requested again."""

    reason: str


@dataclass(frozen=True, slots=True)
class Closed:
    """The session ended; `reason` is a sentence."""

    reason: str


SessionEvent = (
    TopicRegistered | TopicRefused | Ready | MessageReceived | LogLine | Problem | SyncLost | Closed
)
