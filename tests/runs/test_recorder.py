"""The recorder: what a real simulation publishes comes back byte for byte from the MCAP file;
writing stays off the caller's loop; failures are contained; names cannot escape out_dir.
(The /tf helper of server/runs/tf.py is tested here too, as the recording is what it is for.)"""

import math
import os
import statistics
import threading
import time
from dataclasses import dataclass
from pathlib import Path

import pytest
from mcap.reader import make_reader
from mcap.summary import Summary

from sandbox.msgs import MESSAGE_TYPES, Message, UnknownMessageTypeError
from sandbox.msgs.geometry_msgs import Twist, Vector3
from sandbox.msgs.sensor_msgs import LaserScan
from sandbox.msgs.std_msgs import Int32
from sandbox.msgs.tf2_msgs import TFMessage
from server.runs.recorder import (
    Recorder,
    RecorderClosedError,
    RecorderState,
)
from server.runs.safe_paths import safe_name, safe_relative_path
from server.runs.tf import tf_message
from server.sim import Simulation
from tests.waiting import wait_until

NS_PER_S = 1_000_000_000
# Where the crop rover's sensors sit; the YDLidar sweeps clockwise, hence the roll (see tf.py).
FLOAT64_ONLY = {"std_msgs/Int32", "geometry_msgs/Twist", "nav_msgs/Odometry", "tf2_msgs/TFMessage"}
CROP_ROVER_FRAMES = {"laser": (0.0, 0.0, math.pi, math.pi), "imu_link": (0.0, 0.0, 0.0)}


@dataclass(frozen=True)
class Sent:
    topic: str
    type_name: str
    log_time_ns: int
    data: bytes
    message: Message


def record_crop_rover(out_dir: Path, seconds: float = 2.0) -> tuple[dict[str, str], list[Sent]]:
    """Drive the crop rover for `seconds` and record everything, as the run engine will:
    sensor topics as published, /tf at 30 Hz, a Twist command and an Int32 counter at 10 Hz."""
    sim = Simulation("crop_rover", "crop_rows")
    recorder = Recorder(out_dir, "run-42", metadata={"robot": "crop_rover", "world": "crop_rows"})
    for spec in sim.topics:
        recorder.add_topic(spec.name, spec.type_name)
    sent: list[Sent] = []

    def record(topic: str, time_ns: int, message: Message) -> None:
        data = message.serialize()
        recorder.record(topic, message._type, time_ns, data)
        sent.append(Sent(topic, message._type, time_ns, data, message))

    frame_period_s = 1.0 / 30.0
    for frame in range(round(seconds / frame_period_s)):
        if frame % 3 == 0:
            command = Twist(Vector3(0.15, 0.0, 0.0), Vector3(0.0, 0.0, 0.4 * math.sin(frame)))
            now_ns = round(sim.time_s * NS_PER_S)
            sim.apply("cmd_vel", command)
            record("cmd_vel", now_ns, command)
            record("count", now_ns, Int32(frame // 3))
        for published in sim.step(frame_period_s):
            record(published.topic, round(published.time_s * NS_PER_S), published.message)
        pose = sim.state.pose
        now_ns = round(sim.time_s * NS_PER_S)
        record("tf", now_ns, tf_message(now_ns, pose.x, pose.y, pose.yaw, CROP_ROVER_FRAMES))
    return recorder.close(), sent


@pytest.fixture(scope="module")
def recording(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict[str, str], list[Sent]]:
    out_dir = tmp_path_factory.mktemp("run")
    paths, sent = record_crop_rover(out_dir)
    return out_dir, paths, sent


def read_back(path: Path) -> tuple[Summary, list[tuple[str, str, int, bytes]]]:
    """The file's summary and its messages in file order: (topic, schema name, log time, data)."""
    with open(path, "rb") as stream:
        reader = make_reader(stream)
        summary = reader.get_summary()
        assert summary is not None
        messages = [
            (channel.topic, schema.name, message.log_time, message.data)
            for schema, channel, message in reader.iter_messages(log_time_order=False)
        ]
    return summary, messages


# ------------------------------------------------------------------------------- round trip
def test_every_topic_has_a_ros1msg_schema_with_the_full_definition(recording) -> None:
    out_dir, paths, sent = recording
    assert paths["recording"] == str(out_dir / "recording.mcap")
    summary, _ = read_back(out_dir / "recording.mcap")
    channels = {channel.topic: channel for channel in summary.channels.values()}
    expected = {f"/{item.topic}": item.type_name for item in sent}
    assert {"/scan", "/odom", "/imu", "/psi", "/cmd_vel", "/u", "/count", "/tf"} <= set(channels)
    for topic, type_name in expected.items():
        channel = channels[topic]
        schema = summary.schemas[channel.schema_id]
        assert channel.message_encoding == "ros1"
        assert schema.encoding == "ros1msg"
        assert schema.name == type_name
        assert schema.data.decode() == MESSAGE_TYPES[type_name]._full_text
    # add_topic declared the command topic "u" though nothing was sent on it.
    assert summary.statistics.channel_message_counts.get(channels["/u"].id, 0) == 0
    assert {"sensor_msgs/LaserScan", "nav_msgs/Odometry", "tf2_msgs/TFMessage"} <= set(
        expected.values()
    )


def test_messages_come_back_byte_for_byte_in_order(recording) -> None:
    out_dir, _, sent = recording
    _, messages = read_back(out_dir / "recording.mcap")
    assert messages == [(f"/{s.topic}", s.type_name, s.log_time_ns, s.data) for s in sent]
    times = [log_time for _, _, log_time, _ in messages]
    assert times == sorted(times)
    assert 2 * NS_PER_S - times[-1] <= 1_000_000  # 2 s, to the last whole physics tick


def test_recorded_bytes_deserialize_to_the_published_messages(recording) -> None:
    out_dir, _, sent = recording
    _, messages = read_back(out_dir / "recording.mcap")
    scans = 0
    for (_, type_name, _, data), original in zip(messages, sent, strict=True):
        decoded = MESSAGE_TYPES[type_name].deserialize(data)
        assert decoded.serialize() == data
        if isinstance(decoded, LaserScan):
            assert len(decoded.ranges) == 429
            # float32 on the wire: equal to what the sensor computed to single precision.
            assert decoded.ranges == pytest.approx(original.message.ranges, rel=1e-7, abs=1e-30)
            scans += 1
        elif type_name in FLOAT64_ONLY:
            assert decoded == original.message
    assert scans == 13  # 7 Hz from its phase offset 0.143 s up to 1.999 s


def test_run_metadata_is_in_the_file(recording) -> None:
    out_dir, _, _ = recording
    with open(out_dir / "recording.mcap", "rb") as stream:
        reader = make_reader(stream)
        metadata = {record.name: record.metadata for record in reader.iter_metadata()}
        header = reader.get_header()
    assert metadata["run"] == {"run_id": "run-42", "robot": "crop_rover", "world": "crop_rows"}
    assert header.profile == "ros1"


def test_close_twice_returns_the_same_paths_and_record_after_close_is_refused(tmp_path) -> None:
    recorder = Recorder(tmp_path, "r")
    recorder.record_message("count", 0, Int32(1))
    first = recorder.close()
    assert recorder.close() == first
    assert recorder.state is RecorderState.CLOSED and recorder.error is None
    with pytest.raises(RecorderClosedError, match="after close"):
        recorder.record_message("count", 1, Int32(2))
    with pytest.raises(RecorderClosedError, match="after close"):
        recorder.record("other", "std_msgs/Int32", 1, Int32(2).serialize())


def test_wrong_use_fails_at_once_with_a_sentence(tmp_path) -> None:
    with Recorder(tmp_path, "r") as recorder:
        with pytest.raises(UnknownMessageTypeError, match="known types are"):
            recorder.add_topic("scan", "sensor_msgs/LaserScam")
        recorder.add_topic("scan", "sensor_msgs/LaserScan")
        recorder.add_topic("scan", "sensor_msgs/LaserScan")  # idempotent
        with pytest.raises(ValueError, match="'/scan' is recorded as sensor_msgs/LaserScan"):
            recorder.add_topic("/scan", "std_msgs/Int32")
        with pytest.raises(TypeError, match="serialized bytes"):
            recorder.record("count", "std_msgs/Int32", 0, "1")  # type: ignore[arg-type]
        assert recorder.error is None


# ------------------------------------------------------------------------------- off the loop
class SlowRecorder(Recorder):
    """A writer that takes `delay_s` per batch, like a slow disk, and notes its batch sizes."""

    delay_s = 0.002

    def __init__(self, *args, **kwargs) -> None:
        self.batch_bytes: list[int] = []
        super().__init__(*args, **kwargs)

    def _write_batch(self, batch) -> None:
        if batch:
            self.batch_bytes.append(sum(len(data) + 128 for _, _, data in batch))
            time.sleep(self.delay_s)
        super()._write_batch(batch)


def count_messages(path: Path) -> int:
    with open(path, "rb") as stream:
        return sum(1 for _ in make_reader(stream).iter_messages(log_time_order=False))


def test_backpressure_keeps_every_message_within_the_byte_bound(tmp_path) -> None:
    cap = 4096
    recorder = SlowRecorder(tmp_path, "r", max_buffer_bytes=cap)
    payload = Int32(7).serialize()
    for index in range(3000):
        recorder.record("count", "std_msgs/Int32", index, payload)
    recorder.close()
    assert recorder.error is None
    assert count_messages(tmp_path / "recording.mcap") == 3000
    assert len(recorder.batch_bytes) > 20  # the producer really had to wait for the writer
    assert max(recorder.batch_bytes) <= cap


def test_record_does_not_wait_for_a_slow_disk(tmp_path) -> None:
    recorder = SlowRecorder(tmp_path, "r")
    recorder.delay_s = 0.5
    scan = LaserScan(ranges=[1.0] * 429).serialize()
    started = time.perf_counter()
    for index in range(1000):
        recorder.record("scan", "sensor_msgs/LaserScan", index, scan)
    elapsed_s = time.perf_counter() - started
    recorder.close()
    assert elapsed_s < 0.25
    assert count_messages(tmp_path / "recording.mcap") == 1000


def test_record_costs_microseconds_per_laser_scan(tmp_path) -> None:
    scan = LaserScan(ranges=[2.5] * 429, intensities=[1.0] * 429).serialize()
    with Recorder(tmp_path, "bench") as recorder:
        recorder.add_topic("scan", "sensor_msgs/LaserScan")
        costs_ns = []
        for index in range(5000):
            started = time.perf_counter_ns()
            recorder.record("scan", "sensor_msgs/LaserScan", index, scan)
            costs_ns.append(time.perf_counter_ns() - started)
    assert statistics.median(costs_ns) < 20_000  # [ns] typically ~1 us; the loop runs at 1 kHz


# ------------------------------------------------------------------------------- failures
def test_out_dir_that_cannot_be_created_fails_softly(tmp_path) -> None:
    blocker = tmp_path / "a_file"
    blocker.write_text("not a directory")
    recorder = Recorder(blocker / "run", "r")
    assert recorder.state is RecorderState.FAILED
    assert recorder.error is not None and recorder.error.startswith("recording failed: [Errno")
    recorder.record_message("count", 0, Int32(1))  # a no-op, no exception
    assert "recording" not in recorder.close()
    assert recorder.state is RecorderState.FAILED


def test_out_dir_in_proc_fails_softly() -> None:
    recorder = Recorder(Path("/proc/robodojo-recorder-test/run"), "r")
    assert recorder.state is RecorderState.FAILED
    assert recorder.error and recorder.error.startswith("recording failed:")
    recorder.record("count", "std_msgs/Int32", 0, Int32(1).serialize())
    assert recorder.close() == {}


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="needs /dev/full")
def test_disk_full_while_recording_is_contained(tmp_path) -> None:
    (tmp_path / "recording.mcap").symlink_to("/dev/full")  # every write: ENOSPC
    recorder = Recorder(tmp_path, "r", max_buffer_bytes=64 * 1024)
    scan = LaserScan(ranges=[1.0] * 429).serialize()
    deadline = time.monotonic() + 10.0
    index = 0
    while recorder.error is None and time.monotonic() < deadline:
        recorder.record("scan", "sensor_msgs/LaserScan", index, scan)
        index += 1
    assert recorder.error == "recording failed: [Errno 28] No space left on device"
    assert recorder.state is RecorderState.FAILED
    started = time.perf_counter()
    for _ in range(1000):
        recorder.record("scan", "sensor_msgs/LaserScan", index, scan)
    assert time.perf_counter() - started < 0.05  # a cheap no-op now
    assert "recording" not in recorder.close()


def test_bad_data_fails_the_recorder_not_the_caller(tmp_path) -> None:
    recorder = Recorder(tmp_path, "r")
    recorder.record("count", "std_msgs/Int32", -5, Int32(1).serialize())  # no negative time
    recorder.close()
    assert recorder.state is RecorderState.FAILED
    assert recorder.error and recorder.error.startswith("recording failed: ")


def test_a_producer_blocked_by_backpressure_is_released_when_the_writer_fails(tmp_path) -> None:
    class FailingRecorder(Recorder):
        def _write_batch(self, batch) -> None:
            time.sleep(0.05)
            raise OSError(28, "No space left on device")

    recorder = FailingRecorder(tmp_path, "r", max_buffer_bytes=1024)
    payload = Int32(1).serialize()
    done = threading.Event()

    def produce() -> None:
        for index in range(1000):
            recorder.record("count", "std_msgs/Int32", index, payload)
        done.set()

    producer = threading.Thread(target=produce)
    producer.start()
    producer.join(5.0)
    assert done.is_set()
    assert recorder.error == "recording failed: [Errno 28] No space left on device"
    recorder.close()


# ------------------------------------------------------------------------------- files
def test_logs_append_across_calls(tmp_path) -> None:
    recorder = Recorder(tmp_path, "r")
    recorder.write_log("follower", ["step 1", "step 2\n"])
    wait_until(
        lambda: (
            (tmp_path / "logs" / "follower.log").is_file()
            and (tmp_path / "logs" / "follower.log").read_text() == "step 1\nstep 2\n"
        ),
        5,
        "the writer wrote the first part of the log",
    )
    recorder.write_log("follower", ["step 3"])
    recorder.write_log("../../evil", ["escaped?"])
    paths = recorder.close()
    assert (tmp_path / "logs" / "follower.log").read_text() == "step 1\nstep 2\nstep 3\n"
    assert paths["logs"] == str(tmp_path / "logs")
    assert (tmp_path / "logs" / "evil.log").read_text() == "escaped?\n"
    assert sorted(p.name for p in (tmp_path / "logs").iterdir()) == ["evil.log", "follower.log"]


def test_artifact_names_cannot_escape_out_dir(tmp_path) -> None:
    out_dir = tmp_path / "run"
    outside = tmp_path / "outside"
    outside.mkdir()
    recorder = Recorder(out_dir, "r")
    hostile = [
        ("a/../../b", b"1"),
        ("../../outside/x", b"2"),
        ("/etc/passwd", b"3"),
        ("..", b"4"),
        ("", b"5"),
        ("c\\..\\..\\d", b"6"),
        ("plots/speed.png", b"7"),
    ]
    written = recorder.write_artifacts("../outside", hostile)
    written += recorder.write_artifacts("/", [("x", b"8")])
    paths = recorder.close()
    assert recorder.error is None
    assert len(written) == 8
    root = (out_dir / "artifacts").resolve()
    for path in written:
        assert path.resolve().is_relative_to(root)
    assert list(outside.iterdir()) == []
    assert (out_dir / "artifacts" / "outside" / "plots" / "speed.png").read_bytes() == b"7"
    assert (out_dir / "artifacts" / "outside" / "a" / "b").read_bytes() == b"1"
    assert paths["artifacts"] == str(out_dir / "artifacts")


def test_a_symlink_planted_in_artifacts_is_not_followed_out(tmp_path) -> None:
    out_dir, outside = tmp_path / "run", tmp_path / "outside"
    outside.mkdir()
    (out_dir / "artifacts").mkdir(parents=True)
    (out_dir / "artifacts" / "node").symlink_to(outside)
    recorder = Recorder(out_dir, "r")
    assert recorder.write_artifacts("node", [("x", b"1")]) == []
    assert list(outside.iterdir()) == []
    assert recorder.error and "outside" in recorder.error
    recorder.close()


@pytest.mark.parametrize(
    ("name", "expected"),
    [
        ("..", "_"),
        ("...", "_"),
        ("../x", "x"),
        ("../../evil", "evil"),
        ("a b/c", "a_b_c"),
        ("a\\..\\b", "a_b"),
        (".hidden", "hidden"),
        ("ok-name_1.txt", "ok-name_1.txt"),
        ("", "_"),
    ],
)
def test_safe_name(name: str, expected: str) -> None:
    assert safe_name(name) == expected


def test_safe_relative_path_drops_climbing_parts() -> None:
    assert safe_relative_path("a/../../b") == Path("a/b")
    assert safe_relative_path("/abs/x.csv") == Path("abs/x.csv")
    assert not safe_relative_path("../../..").is_absolute()


def test_write_json_replaces_non_finite_numbers(tmp_path) -> None:
    recorder = Recorder(tmp_path, "r")
    recorder.write_json("metrics", {"collisions": 2, "p99_ms": float("inf"), "x": [float("nan")]})
    paths = recorder.close()
    assert paths["metrics"] == str(tmp_path / "metrics.json")
    text = (tmp_path / "metrics.json").read_text()
    assert '"p99_ms": null' in text and "NaN" not in text
    assert sorted(p.name for p in tmp_path.iterdir()) == ["metrics.json", "recording.mcap"]


# ------------------------------------------------------------------------------- tf
def rotate(quaternion, vector: tuple[float, float, float]) -> tuple[float, float, float]:
    """v' = q v q* for a unit quaternion."""
    qx, qy, qz, qw = quaternion.x, quaternion.y, quaternion.z, quaternion.w
    vx, vy, vz = vector
    # t = 2 q_vec x v; v' = v + w t + q_vec x t
    tx, ty, tz = 2 * (qy * vz - qz * vy), 2 * (qz * vx - qx * vz), 2 * (qx * vy - qy * vx)
    return (
        vx + qw * tx + (qy * tz - qz * ty),
        vy + qw * ty + (qz * tx - qx * tz),
        vz + qw * tz + (qx * ty - qy * tx),
    )


@pytest.mark.parametrize(
    ("msg_type", "md5"),
    [
        ("geometry_msgs/Transform", "ac9eff44abf714214112b05d54a3cf9b"),
        ("geometry_msgs/TransformStamped", "b5764a33bfeb3588febc2682852579b0"),
        ("tf2_msgs/TFMessage", "94810edda583a504dfda3829e70d7eec"),
    ],
)
def test_tf_types_have_the_ros_md5sums(msg_type: str, md5: str) -> None:
    assert MESSAGE_TYPES[msg_type]._md5sum == md5


def test_tf_message_is_a_tree_under_map() -> None:
    frames = {f"ultrasonic_{i}": (0.1, 0.0, math.radians(30 * i - 90)) for i in range(7)}
    message = tf_message(1_500_000_123, 2.0, -1.0, math.pi / 2, frames, odom_origin=(1, 1, 0))
    assert isinstance(message, TFMessage)
    parents = {t.child_frame_id: t.header.frame_id for t in message.transforms}
    assert parents == {"base_link": "map", "odom": "map", **dict.fromkeys(frames, "base_link")}
    for transform in message.transforms:
        assert (transform.header.stamp.secs, transform.header.stamp.nsecs) == (1, 500_000_123)
    base = message.transforms[0].transform
    assert (base.translation.x, base.translation.y, base.translation.z) == (2.0, -1.0, 0.0)
    assert rotate(base.rotation, (1, 0, 0)) == pytest.approx((0, 1, 0), abs=1e-12)
    assert TFMessage.deserialize(message.serialize()) == message


def test_upside_down_laser_frame_turns_the_clockwise_lidar_into_robot_directions() -> None:
    laser = tf_message(0, 0.0, 0.0, 0.0, CROP_ROVER_FRAMES).transforms[1]
    assert laser.child_frame_id == "laser"
    for lidar_angle in (0.0, 0.3, math.pi / 2, -2.0):
        beam = (math.cos(lidar_angle), math.sin(lidar_angle), 0.0)
        robot_direction = math.pi - lidar_angle  # lidar.py: robot direction = pi - lidar angle
        expected = (math.cos(robot_direction), math.sin(robot_direction), 0.0)
        assert rotate(laser.transform.rotation, beam) == pytest.approx(expected, abs=1e-12)


def test_tf_message_refuses_frames_that_break_the_tree() -> None:
    with pytest.raises(ValueError, match="second parent"):
        tf_message(0, 0.0, 0.0, 0.0, {"base_link": (0.0, 0.0, 0.0)})
    with pytest.raises(ValueError, match="x \\[m\\], y \\[m\\], yaw"):
        tf_message(0, 0.0, 0.0, 0.0, {"laser": (0.0, 0.0)})  # type: ignore[dict-item]
    with pytest.raises(ValueError, match="finite"):
        tf_message(0, float("nan"), 0.0, 0.0, {})
