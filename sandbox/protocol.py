"""The wire between the server (parent) and a sandboxed node (child).

Frames are msgspec Structs, msgpack-encoded, each preceded by its length as a little-endian
uint32, on two inherited pipes: one parent -> child, one child -> parent. The node's stdout and
stderr are a third pipe (the log stream), so nothing the student prints can corrupt a frame.

A node's life, as the parent sees it:

    child:  Ready                                   (imports done, sandbox sealed, idle in pool)
    parent: Load(code, info)
    child:  Yield(wake_at, published, graph)         (setup ran; first sleep)
    parent: Wake(time, deliveries)      <-- repeated: the node runs until it sleeps again
    child:  Yield(...)
    parent: Shutdown(reason)           (or the node ends by itself)
    child:  Finishing(reason, published)   (hooks, figures and files still to come)
    child:  Exited(outcome, error, artifacts, notes)

Every message payload crosses as ROS1 bytes with its type name (`Envelope`), so the wire format
of a message is defined once, in sandbox.msgs.
"""

from __future__ import annotations

import os
import struct
from enum import StrEnum

import msgspec

MAX_FRAME_BYTES = 64 * 1024 * 1024  # [bytes] artifacts travel in frames; caps keep them below
_LENGTH = struct.Struct("<I")


class Clock(StrEnum):
    """LOCKSTEP: virtual time, the node's clock functions follow simulated time.
    REALTIME: the wall clock."""

    LOCKSTEP = "lockstep"
    REALTIME = "realtime"


class Api(StrEnum):
    AUTO = "auto"  # a file defining step() uses the step API, anything else runs as a script
    STEP = "step"
    ROSPY = "rospy"
    # Not a node: a one-shot job that reads a ROS 2 Python launch file (Load.code, named
    # Load.filename, with the workspace in Load.files and `name:=value` arguments in
    # NodeInfo.argv) and ends with Exited carrying the plan (sandbox/launch2/job.py).
    LAUNCH = "launch"


class Outcome(StrEnum):
    FINISHED = "finished"  # the script returned, or signal_shutdown() was called
    SHUTDOWN = "shutdown"  # the parent asked it to stop
    ERROR = "error"  # the student's code raised
    # Set by the parent, never sent by a child:
    KILLED = "killed"  # exceeded a budget (step time, start-up) and was killed
    CRASHED = "crashed"  # the process died without saying why (signal, memory, broken pipe)


class TopicDecl(msgspec.Struct, frozen=True):
    """A topic and its ROS type name, e.g. ("Distance", "std_msgs/Int32"). `latch`: the
    publisher's last message goes to every later subscriber too (rospy's latch=True).

    ROS 2 QoS, as far as it changes what a node receives (sandbox/ros_compat2/rclpy/qos.py):
    `best_effort` - a publisher offers, or a subscription requests, BEST_EFFORT (a RELIABLE
    subscription gets nothing from a BEST_EFFORT publisher); `latch` on a subscription - it
    requests TRANSIENT_LOCAL (a VOLATILE publisher does not reach it); `volatile` on a
    subscription - it takes no latched history (ROS 2's default; rospy's subscribers always do).
    """

    name: str
    type: str
    latch: bool = False
    best_effort: bool = False
    volatile: bool = False


class RobotTopic(msgspec.Struct, frozen=True):
    """One of the robot's topics: direction is "publish" (a sensor) or "subscribe" (a command)."""

    name: str
    type: str
    direction: str
    rate_hz: float | None = None
    # Every type a command topic takes, when it takes more than `type`: a ROS 2 robot's Twist
    # topic also takes TwistStamped (ROS 2 Jazzy's TurtleBot3 sends it). Empty: just `type`.
    accepts: list[str] = []


class NodeInfo(msgspec.Struct, frozen=True):
    """What a node is told about its run when its code is loaded."""

    node_name: str
    robot: str
    robot_topics: list[RobotTopic]
    velocity_topic: str | None
    clock: Clock
    start_time_s: float = 0.0
    default_rate_hz: float = 10.0
    params: dict[str, object] = {}
    # As in rospy, a node may publish and subscribe to any topic name (debug topics, topics
    # between nodes, topics nobody listens to); a name close to one of the robot's topics gets a
    # warning in the log instead ("did you mean 'Distance'?"). False refuses new names.
    allow_new_topics: bool = True
    # The node's command line after its file name, as rosrun passes it: `_speed:=0.2` sets the
    # private parameter ~speed, `scan:=base_scan` remaps a name; rospy.myargv() drops both.
    argv: list[str] = []
    # Name remappings from a launch file's <remap> or `robodojo run --remap FROM:=TO`.
    remaps: dict[str, str] = {}
    # The node's namespace (a launch file's <group ns="...">, or <node ns="...">).
    namespace: str = "/"
    # 1: rospy; 2: rclpy. A run is one or the other (docs/architecture.md, "ROS 2"): for 2 every
    # type name is a ROS 2 name ("std_msgs/msg/Int32") and every Envelope carries CDR bytes.
    ros_version: int = 1


class Envelope(msgspec.Struct, array_like=True, frozen=True, omit_defaults=True):
    """One ROS message on a topic: its type name and serialized bytes (ROS1 wire format in a
    ROS 1 run, CDR with its encapsulation header in a ROS 2 run; NodeInfo.ros_version).

    On the way to a ROS 2 subscriber the bus may add who published it (when the topic has a
    BEST_EFFORT publisher) and whether it is a latched topic's history replayed to a late
    subscriber: each rclpy subscription applies its own QoS with them."""

    topic: str
    type: str
    data: bytes
    publisher: str = ""
    replayed: bool = False


class Artifact(msgspec.Struct, frozen=True):
    name: str
    data: bytes


class NodeError(msgspec.Struct, frozen=True):
    """An exception in the student's code, with the traceback cut to the student's frames."""

    type: str
    message: str
    filename: str
    line: int | None
    traceback: str


# ----------------------------------------------------------------------- parent -> child
class Load(msgspec.Struct, tag=True, frozen=True):
    code: str
    filename: str
    api: Api
    info: NodeInfo
    # The student's workspace data files (CSV, YAML, ...), written into the node's working
    # directory before its code runs; relative paths, no "..".
    files: list[Artifact] = []


class GraphTopic(msgspec.Struct, array_like=True, frozen=True):
    """One topic of the run's graph as nodes see it (rospy.get_published_topics, services).
    The publishers that offer BEST_EFFORT and those that latch (TRANSIENT_LOCAL) let a ROS 2
    subscription say which publisher's QoS is incompatible with its own, as rclpy logs it."""

    name: str
    type: str
    publishers: list[str]
    subscribers: list[str]
    best_effort_publishers: list[str] = []
    latched_publishers: list[str] = []


class Wake(msgspec.Struct, tag=True, frozen=True):
    time_s: float
    deliveries: list[Envelope]
    # The run's topic graph, sent only when it changed since this node's previous wake.
    graph: list[GraphTopic] | None = None


class Shutdown(msgspec.Struct, tag=True, frozen=True):
    reason: str


# ----------------------------------------------------------------------- child -> parent
class Ready(msgspec.Struct, tag=True, frozen=True):
    pid: int
    python: str
    startup_ms: float


class Yield(msgspec.Struct, tag=True, frozen=True):
    """The node sleeps until `wake_at_s` (None: until a message arrives, as in spin()) after
    publishing `published`. `advertised`/`subscribed` list topics new since the last Yield."""

    wake_at_s: float | None
    published: list[Envelope]
    advertised: list[TopicDecl] = []
    subscribed: list[TopicDecl] = []
    # Topics whose next message wakes the node before `wake_at_s` (a service's requests, the
    # topic of wait_for_message, every subscription while spinning with a timer). None: only
    # `wake_at_s`, or any message when `wake_at_s` is None (spin()).
    wake_on: list[str] | None = None
    unsubscribed: list[str] = []


class Drawing(msgspec.Struct, tag=True, frozen=True):
    """The node started saving a figure: rendering a large PNG takes seconds, so the step it
    is in gets the end budget instead of the step budget (sent at most once per wake)."""


class LibraryLoading(msgspec.Struct, tag=True, frozen=True):
    """A module the node's code has just used for the first time is loading (`done` False), or
    has loaded (`done` True): one whose import runs at its first use in a node started cold,
    such as matplotlib.pyplot (sandbox/host.py, DEFERRED_MODULES). The step's clock stops in
    between, so the load is the library's cost, not the controller's, and only the load: the
    rest of the step keeps its budget (sent in pairs, from the node's main thread)."""

    done: bool


class Finishing(msgspec.Struct, tag=True, frozen=True):
    """The node has ended its part in the run (signal_shutdown(), its script returned or
    raised) and is finishing: shutdown hooks, figures, files. It will not sleep again; its
    Exited follows within the end budget (sandbox/limits.py)."""

    reason: str
    published: list[Envelope] = []


class Exited(msgspec.Struct, tag=True, frozen=True):
    outcome: Outcome
    reason: str
    error: NodeError | None = None
    artifacts: list[Artifact] = []
    notes: list[str] = []
    published: list[Envelope] = []


ToChild = Load | Wake | Shutdown
ToParent = Ready | Yield | Drawing | LibraryLoading | Finishing | Exited


class ProtocolError(RuntimeError):
    """The other side broke the protocol (closed the pipe, sent garbage, a frame too big)."""


class FrameWriter:
    def __init__(self, fd: int) -> None:
        self._fd = fd
        self._encoder = msgspec.msgpack.Encoder()

    def send(self, frame: msgspec.Struct) -> None:
        payload = self._encoder.encode(frame)
        data = _LENGTH.pack(len(payload)) + payload
        written = os.write(self._fd, data)  # one write for any frame that fits the pipe
        if written < len(data):
            view = memoryview(data)[written:]
            while view:
                view = view[os.write(self._fd, view) :]


class FrameReader:
    """Reads whole frames from a blocking or non-blocking pipe."""

    def __init__(self, fd: int, frame_type: object) -> None:
        self._fd = fd
        self._decoder = msgspec.msgpack.Decoder(frame_type)
        self._buffer = bytearray()

    def fileno(self) -> int:
        return self._fd

    def pending(self) -> msgspec.Struct | None:
        """A complete frame already buffered, or None."""
        if len(self._buffer) < 4:
            return None
        (length,) = _LENGTH.unpack_from(self._buffer)
        if length > MAX_FRAME_BYTES:
            raise ProtocolError(f"frame of {length} bytes exceeds the {MAX_FRAME_BYTES} limit")
        if len(self._buffer) < 4 + length:
            return None
        payload = bytes(self._buffer[4 : 4 + length])
        del self._buffer[: 4 + length]
        try:
            return self._decoder.decode(payload)
        except msgspec.DecodeError as error:
            raise ProtocolError(f"undecodable frame: {error}") from None

    def feed(self) -> bool:
        """Read what the pipe has (blocking if the fd blocks); False at end of file."""
        try:
            chunk = os.read(self._fd, 1 << 16)
        except BlockingIOError:
            return True
        if not chunk:
            return False
        self._buffer += chunk
        return True

    def receive(self) -> msgspec.Struct:
        """Block until one whole frame has arrived (for blocking fds)."""
        while True:
            frame = self.pending()
            if frame is not None:
                return frame
            if not self.feed():
                raise ProtocolError("the other side closed the pipe")
