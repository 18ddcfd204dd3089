"""rosserial_msgs types the protocol itself uses: TopicInfo (negotiation) and Log.

Definitions as in ros-drivers/rosserial rosserial_msgs/msg (noetic-devel); their md5sums
(TopicInfo 0ad51f88fc44892f8c10684077646005, Log 11abd731c25933261cd6183bd12d6295) are derived by
sandbox.msgs exactly as genmsg does, and checked in tests against ros_lib's generated headers.
They are not registered in sandbox.msgs' registry (``register=False``): they are protocol
plumbing, not topics a student or a robot can use.
"""

from __future__ import annotations

from enum import IntEnum

from sandbox.msgs import Message


class TopicInfo(Message, register=False):
    """One publisher or subscriber a device advertises (payload of ids 0 and 1)."""

    _type = "rosserial_msgs/TopicInfo"
    _definition = """
# special topic_ids
uint16 ID_PUBLISHER=0
uint16 ID_SUBSCRIBER=1
uint16 ID_SERVICE_SERVER=2
uint16 ID_SERVICE_CLIENT=4
uint16 ID_PARAMETER_REQUEST=6
uint16 ID_LOG=7
uint16 ID_TIME=10
uint16 ID_TX_STOP=11

# The endpoint ID for this topic
uint16 topic_id

string topic_name
string message_type

# MD5 checksum for this message type
string md5sum

# size of the buffer message must fit in
int32 buffer_size
"""


class Log(Message, register=False):
    """A log line from the device (payload of id 7): nh.loginfo() and friends."""

    _type = "rosserial_msgs/Log"
    _definition = """
#ROS Logging Levels
uint8 ROSDEBUG=0
uint8 INFO=1
uint8 WARN=2
uint8 ERROR=3
uint8 FATAL=4

uint8 level
string msg
"""


class LogLevel(IntEnum):
    """rosserial_msgs/Log levels."""

    DEBUG = 0
    INFO = 1
    WARN = 2
    ERROR = 3
    FATAL = 4
