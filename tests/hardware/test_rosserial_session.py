"""session.py without sockets: bytes in, events and bytes out, time under the test's control."""

from __future__ import annotations

import dataclasses

import pytest

from sandbox.msgs.geometry_msgs import Twist, Vector3
from sandbox.msgs.std_msgs import Bool, Int32, Int32MultiArray
from server.hardware.rosserial.events import (
    Closed,
    Direction,
    LogLine,
    MessageReceived,
    Problem,
    Ready,
    SyncLost,
    TopicRefused,
    TopicRegistered,
)
from server.hardware.rosserial.frames import (
    REQUEST_TOPICS_FRAME,
    TX_STOP_FRAME,
    FrameParser,
    TopicId,
    encode_frame,
)
from server.hardware.rosserial.limits import DEFAULT_LIMITS, RosserialLimits
from server.hardware.rosserial.messages import LogLevel
from server.hardware.rosserial.session import (
    RATE_LIMITED,
    RobotDisconnected,
    RosserialSession,
    SessionError,
    SessionState,
    TopicError,
)
from tests.hardware.crowbot_firmware import (
    PROTOCOL_VER1,
    PUBLISHER_IDS,
    SUBSCRIBER_IDS,
    WRONG_MD5,
    log_payload,
    negotiation_frames,
    ros_lib_frame,
    topic_info_payload,
)

# The paper's serial_node log (Fig. 6) was taken at 1692905636.631129 s.
WALL_NS = 1_692_905_636_631_129_000  # [ns] since the epoch
T0 = 100.0  # [s] monotonic time the session starts at


def started(**limits: float) -> RosserialSession:
    session = RosserialSession(
        clock_ns=lambda: WALL_NS, limits=dataclasses.replace(DEFAULT_LIMITS, **limits)
    )
    session.start(T0)
    return session


def negotiated(**limits: float) -> RosserialSession:
    session = started(**limits)
    session.receive_data(b"".join(negotiation_frames()), T0 + 0.01)
    session.data_to_send()
    return session


def distance_frame(value: int) -> bytes:
    return ros_lib_frame(PUBLISHER_IDS["Distance"], Int32(value).serialize())


def sent_frames(session: RosserialSession) -> list[tuple[int, bytes]]:
    return [(f.topic_id, f.payload) for f in FrameParser().feed(session.data_to_send())]


# ----------------------------------------------------------------------------- negotiation
def test_start_requests_topics() -> None:
    session = RosserialSession()
    assert session.state is SessionState.CONNECTING
    with pytest.raises(SessionError, match=r"call start\(\) before receive_data"):
        session.receive_data(b"\xff", T0)
    session.start(T0)
    assert session.state is SessionState.NEGOTIATING
    assert session.data_to_send() == REQUEST_TOPICS_FRAME
    with pytest.raises(SessionError, match="cannot go from negotiating to negotiating"):
        session.start(T0)


def test_the_crowbot_negotiation_registers_seven_topics_and_answers_the_time() -> None:
    session = started()
    session.data_to_send()
    events = session.receive_data(b"".join(negotiation_frames()), T0 + 0.01)
    registered = [e.topic for e in events if isinstance(e, TopicRegistered)]
    assert [(t.name, t.direction, t.topic_id) for t in registered] == [
        ("Distance", Direction.PUBLISHES, 125),
        ("Button", Direction.PUBLISHES, 126),
        ("Light", Direction.PUBLISHES, 127),
        ("Line", Direction.PUBLISHES, 128),
        ("Control", Direction.SUBSCRIBES, 100),
        ("Leds", Direction.SUBSCRIBES, 101),
        ("Buzzer", Direction.SUBSCRIBES, 102),
    ]
    assert {t.buffer_size for t in registered} == {512}
    assert session.subscribers["Control"].message_class is Twist
    # The time request (a zeroed std_msgs/Time) is answered with the injected clock.
    secs, nsecs = divmod(WALL_NS, 1_000_000_000)
    answer = secs.to_bytes(4, "little") + nsecs.to_bytes(4, "little")
    assert session.data_to_send() == encode_frame(TopicId.TIME, answer)
    assert session.synced and session.stats.time_requests == 1
    assert session.state is SessionState.NEGOTIATING  # the robot has not published yet
    events = session.receive_data(distance_frame(42), T0 + 0.05)
    assert events == [Ready(), MessageReceived("Distance", Int32(42))]
    assert session.state is SessionState.READY and session.problems == []


def test_a_robot_that_only_subscribes_is_ready_once_advertising_settles() -> None:
    session = started(settle_s=0.5)
    session.receive_data(b"".join(negotiation_frames()), T0)
    assert session.poll(T0 + 0.4) == []
    assert session.poll(T0 + 0.5) == [Ready()]
    assert session.poll(T0 + 0.6) == []


def test_advertising_again_after_a_new_request_changes_nothing() -> None:
    session = negotiated()
    session.receive_data(distance_frame(1), T0 + 0.1)
    events = session.receive_data(b"".join(negotiation_frames()), T0 + 0.2)
    assert not [e for e in events if isinstance(e, TopicRegistered | Ready)]
    assert session.state is SessionState.READY


def test_an_md5_mismatch_is_refused_with_both_sums() -> None:
    session = started()
    events = session.receive_data(
        b"".join(negotiation_frames(frozenset({"Distance", "Control"}))), T0
    )
    refused = [e for e in events if isinstance(e, TopicRefused)]
    assert [(r.name, r.message_type) for r in refused] == [
        ("Distance", "std_msgs/Int32"),
        ("Control", "geometry_msgs/Twist"),
    ]
    (distance_problem, control_problem) = session.problems
    assert Int32._md5sum in distance_problem and WRONG_MD5 in distance_problem
    assert "Checksum does not match" in distance_problem and "'Distance'" in distance_problem
    assert Twist._md5sum in control_problem and WRONG_MD5 in control_problem
    assert [e.text for e in events if isinstance(e, Problem)] == session.problems
    assert "Distance" not in session.publishers and "Control" not in session.subscribers
    # Frames on the refused topic are not delivered; commands to it are refused.
    assert not any(
        isinstance(e, MessageReceived) for e in session.receive_data(distance_frame(1), T0 + 1)
    )
    with pytest.raises(TopicError, match="does not subscribe to 'Control'"):
        session.send("Control", Twist())


def test_an_unknown_message_type_is_refused_with_a_sentence() -> None:
    session = started()
    md5 = "863b248d5016ca62ea2e895ae5265cf9"  # turtlesim/Pose
    info = topic_info_payload(125, "Pose", "turtlesim/Pose", md5, 512)
    events = session.receive_data(ros_lib_frame(TopicId.PUBLISHER, info), T0)
    assert events[0] == TopicRefused("Pose", "turtlesim/Pose", session.problems[0])
    assert "no message type 'turtlesim/Pose'" in session.problems[0]
    assert "863b248d5016ca62ea2e895ae5265cf9" in session.problems[0]
    assert "std_msgs" in session.problems[0]  # the sentence says which packages exist


def test_a_topic_on_a_reserved_id_is_refused() -> None:
    session = started()
    info = topic_info_payload(7, "Distance", "std_msgs/Int32", Int32._md5sum, 512)
    session.receive_data(ros_lib_frame(TopicId.PUBLISHER, info), T0)
    assert "reserved id 7" in session.problems[0]


# ----------------------------------------------------------------------------- traffic
def test_log_frames_become_log_lines() -> None:
    session = negotiated()
    events = session.receive_data(ros_lib_frame(TopicId.LOG, log_payload(2, "low battery")), T0)
    assert events == [LogLine(LogLevel.WARN, "low battery")]


def test_every_sensor_topic_decodes() -> None:
    session = negotiated()
    light = Int32MultiArray(data=[2451, 2461])
    data = (
        ros_lib_frame(PUBLISHER_IDS["Button"], Bool(True).serialize())
        + ros_lib_frame(PUBLISHER_IDS["Light"], light.serialize())
        + ros_lib_frame(PUBLISHER_IDS["Line"], Int32MultiArray(data=[1840, 1855]).serialize())
    )
    events = session.receive_data(data, T0 + 0.1)
    assert events[1:] == [
        MessageReceived("Button", Bool(True)),
        MessageReceived("Light", light),
        MessageReceived("Line", Int32MultiArray(data=[1840, 1855])),
    ]


def test_send_encodes_for_the_robots_subscriber_id() -> None:
    session = negotiated()
    command = Twist(linear=Vector3(x=0.1), angular=Vector3(z=-0.5))
    session.send("Control", command)
    assert sent_frames(session) == [(SUBSCRIBER_IDS["Control"], command.serialize())]
    assert session.stats.messages_out == 1


def test_send_refuses_with_sentences() -> None:
    session = negotiated()
    with pytest.raises(TopicError, match="does not subscribe to 'Motor'; it subscribes to: Buzzer"):
        session.send("Motor", Twist())
    with pytest.raises(TopicError, match="'Distance' is a topic the robot publishes"):
        session.send("Distance", Int32(3))
    with pytest.raises(TopicError, match="'Control' carries geometry_msgs/Twist, got std_msgs"):
        session.send("Control", Bool(True))
    with pytest.raises(TopicError, match="does not fit the robot's 512-byte receive buffer"):
        session.send("Leds", Int32MultiArray(data=list(range(200))))
    assert session.data_to_send() == b""


def test_send_before_any_subscriber_is_advertised() -> None:
    session = started()
    with pytest.raises(TopicError, match="it subscribes to: nothing yet"):
        session.send("Control", Twist())


def test_stop_sends_tx_stop_and_closes() -> None:
    session = negotiated()
    assert session.stop() == [Closed("stopped by RoboDojo (tx stop sent)")]
    assert session.data_to_send() == TX_STOP_FRAME
    assert session.state is SessionState.CLOSED
    assert session.stop() == [] and session.data_to_send() == b""
    with pytest.raises(RobotDisconnected, match=r"disconnected .*stopped by RoboDojo"):
        session.send("Control", Twist())
    with pytest.raises(SessionError, match="closed session"):
        session.receive_data(distance_frame(1), T0)
    assert session.poll(T0 + 1000) == []


@pytest.mark.parametrize(
    ("state", "target"),
    [
        (SessionState.CONNECTING, SessionState.READY),
        (SessionState.READY, SessionState.NEGOTIATING),
        (SessionState.CLOSED, SessionState.NEGOTIATING),
        (SessionState.CLOSED, SessionState.READY),
    ],
)
def test_illegal_transitions_raise(state: SessionState, target: SessionState) -> None:
    session = RosserialSession()
    session.state = state
    with pytest.raises(SessionError, match=f"cannot go from {state} to {target}"):
        session._transition(target)


# ----------------------------------------------------------------------------- timers
def test_a_robot_that_never_asks_the_time_is_unable_to_sync() -> None:
    session = started(sync_timeout_s=15.0, idle_timeout_s=30.0)
    session.data_to_send()
    assert session.poll(T0 + 14.9) == []
    (lost,) = session.poll(T0 + 15.1)
    assert isinstance(lost, SyncLost) and lost.reason.startswith("unable to sync")
    assert session.data_to_send() == REQUEST_TOPICS_FRAME  # requested again


def test_sync_is_lost_without_time_requests_then_the_silent_link_is_closed() -> None:
    session = negotiated(sync_timeout_s=15.0, idle_timeout_s=30.0)
    session.receive_data(distance_frame(1), T0 + 1.0)
    (lost,) = session.poll(T0 + 15.1)
    assert isinstance(lost, SyncLost) and lost.reason.startswith("lost sync with the robot")
    assert session.data_to_send() == REQUEST_TOPICS_FRAME and not session.synced
    (closed,) = session.poll(T0 + 31.1)
    assert isinstance(closed, Closed) and "sent nothing for 30 s" in closed.reason
    assert session.state is SessionState.CLOSED


def test_the_second_sync_warning_says_the_robot_did_ask_before() -> None:
    session = negotiated(sync_timeout_s=15.0, idle_timeout_s=100.0)
    session.receive_data(distance_frame(1), T0 + 1.0)
    (first,) = session.poll(T0 + 15.1)
    assert first.reason.startswith("lost sync with the robot")
    session.receive_data(distance_frame(2), T0 + 20.0)  # data, but no time request
    (second,) = session.poll(T0 + 30.2)
    assert isinstance(second, SyncLost)
    assert "never asked" not in second.reason
    assert second.reason.startswith("still no sync with the robot: its last time request came 30 s")


def test_frames_sent_before_the_topics_are_advertised_are_no_problem_once_they_are() -> None:
    session = started()
    session.data_to_send()
    # ros_lib after a reconnection: it publishes before it answers the topic request.
    session.receive_data(distance_frame(1), T0 + 0.01)
    assert any("Tried to publish before configured, topic id 125" in p for p in session.problems)
    session.receive_data(b"".join(negotiation_frames()), T0 + 0.02)
    assert session.problems == []  # the clean handshake explained it
    # A frame on an id the robot never advertised stays a problem.
    session.receive_data(ros_lib_frame(160, Int32(7).serialize()), T0 + 0.03)
    assert any("topic id 160" in p for p in session.problems)


def test_regular_time_requests_keep_the_sync() -> None:
    session = negotiated(sync_timeout_s=15.0)
    for second in range(0, 60, 3):
        session.receive_data(ros_lib_frame(TopicId.TIME, bytes(8)), T0 + second)
        assert not [e for e in session.poll(T0 + second + 0.1) if isinstance(e, SyncLost)]
    assert session.stats.time_requests == 21


def test_a_peer_that_advertises_nothing_is_closed() -> None:
    session = started(negotiation_timeout_s=45.0, sync_timeout_s=100.0, idle_timeout_s=100.0)
    session.receive_data(b"hello", T0 + 44.0)
    assert session.poll(T0 + 44.0) == []
    (closed,) = session.poll(T0 + 45.5)
    assert isinstance(closed, Closed) and "is this a rosserial client" in closed.reason


def test_a_stalled_bogus_header_is_abandoned_after_the_frame_timeout() -> None:
    session = negotiated(frame_timeout_s=1.0)
    bogus = bytes([0xFF, 0xFE, 200, 0, 55, 0x7D, 0x00])
    assert session.receive_data(bogus + distance_frame(9), T0 + 1.0) == []
    assert session.poll(T0 + 1.5) == [Ready()]  # advertising settled; the frame still held
    assert session.poll(T0 + 2.1) == [MessageReceived("Distance", Int32(9))]
    assert session.drops["truncated"] == 1


# ----------------------------------------------------------------------------- bad input
def test_frames_on_unknown_topic_ids_request_topics_again_at_most_once_a_second() -> None:
    session = negotiated(request_topics_interval_s=1.0)
    unknown = ros_lib_frame(160, Int32(1).serialize())
    (problem,) = session.receive_data(unknown, T0 + 5.0)
    assert "Tried to publish before configured, topic id 160" in problem.text
    assert session.data_to_send() == REQUEST_TOPICS_FRAME
    assert session.receive_data(unknown * 5, T0 + 5.5) == []  # said once, not re-requested
    assert session.data_to_send() == b""
    session.receive_data(unknown, T0 + 6.1)
    assert session.data_to_send() == REQUEST_TOPICS_FRAME
    assert session.stats.unknown_topic_frames == 7


def test_an_undecodable_message_is_counted_not_raised() -> None:
    session = negotiated()
    (problem,) = session.receive_data(ros_lib_frame(PUBLISHER_IDS["Distance"], b"\x01\x02"), T0)
    assert "not a valid std_msgs/Int32" in problem.text
    assert session.stats.undecodable == 1


def test_data_frames_over_the_rate_limit_are_dropped_and_counted() -> None:
    session = negotiated(max_frames_per_s=10)
    events = session.receive_data(distance_frame(1) * 25, T0 + 1.0)
    assert sum(isinstance(e, MessageReceived) for e in events) == 10
    assert session.drops[RATE_LIMITED] == 15
    events = session.receive_data(distance_frame(1) * 5, T0 + 2.1)  # a new second
    assert sum(isinstance(e, MessageReceived) for e in events) == 5


def test_a_groovy_client_is_told_apart_with_a_sentence() -> None:
    session = started()
    events = session.receive_data(b"".join(negotiation_frames(version=PROTOCOL_VER1)), T0)
    (problem,) = [e for e in events if isinstance(e, Problem)]
    assert "Mismatched protocol version in packet (0xff)" in problem.text
    assert "Rev 0 (rosserial 0.4 and earlier, ROS Groovy)" in problem.text
    assert session.drops["wrong_protocol_version"] >= 8
    assert session.publishers == {}


def test_services_and_parameters_are_explained() -> None:
    session = negotiated()
    md5 = "d41d8cd98f00b204e9800998ecf8427e"  # std_srvs/Empty
    service = topic_info_payload(129, "reset", "std_srvs/Empty", md5, 512)
    param = (4).to_bytes(4, "little") + b"gain"
    events = session.receive_data(
        ros_lib_frame(TopicId.SERVICE_SERVER, service)
        + ros_lib_frame(TopicId.PARAMETER_REQUEST, param)
        + ros_lib_frame(TopicId.TX_STOP, b""),
        T0,
    )
    assert [type(e) for e in events] == [Problem, Problem]
    assert "service 'reset'" in session.problems[0]
    assert "parameter 'gain'" in session.problems[1]
    assert session.stats.reserved_ignored == 1


def test_problems_are_kept_once_and_bounded() -> None:
    session = negotiated(max_problems=3)
    for topic_id in range(160, 170):
        session.receive_data(ros_lib_frame(topic_id, b""), T0 + topic_id)
    assert len(session.problems) == 3


def test_the_outbox_is_bounded() -> None:
    session = negotiated(max_outbox_bytes=1024)
    for _ in range(100):
        session.send("Control", Twist())
    assert len(session.data_to_send()) <= 1024
    assert session.stats.outbox_dropped > 0


def test_limits_must_be_positive() -> None:
    with pytest.raises(ValueError, match=r"RosserialLimits\.idle_timeout_s must be positive"):
        dataclasses.replace(DEFAULT_LIMITS, idle_timeout_s=0)
    assert isinstance(DEFAULT_LIMITS, RosserialLimits)
