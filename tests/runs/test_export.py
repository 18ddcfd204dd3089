"""CSV export: one file per topic, dotted columns, one row per message, values that read back."""

import csv
import json
from pathlib import Path

import numpy as np
import pytest
from mcap.writer import Writer

from sandbox.msgs import MESSAGE_TYPES, Message, Time
from sandbox.msgs.geometry_msgs import Twist, Vector3
from sandbox.msgs.sensor_msgs import Range
from sandbox.msgs.std_msgs import Bool, Header, Int32, String
from server.runs.export import _columns, _row, csv_file_name, export_csv
from server.runs.recorder import Recorder
from server.runs.tf import tf_message
from server.sim import Simulation

NS_PER_S = 1_000_000_000


def write_recording(out_dir: Path) -> dict[str, list[tuple[int, Message]]]:
    """A 1 s crop-rover recording plus hand-made topics; returns what went in, per topic."""
    sim = Simulation("crop_rover", "crop_rows")
    recorder = Recorder(out_dir, "export")
    sent: dict[str, list[tuple[int, Message]]] = {}

    def record(topic: str, time_ns: int, message: Message) -> None:
        recorder.record_message(topic, time_ns, message)
        sent.setdefault(topic, []).append((time_ns, message))

    recorder.add_topic("silent", "std_msgs/Int32")
    sent["silent"] = []
    for frame in range(20):
        now_ns = frame * 50_000_000
        record("cmd_vel", now_ns, Twist(Vector3(0.1 * frame, 0, 0), Vector3(0, 0, -0.5)))
        record("count", now_ns, Int32(frame - 3))
        record("button", now_ns, Bool(frame % 2 == 0))
        record("note", now_ns, String(f'step {frame}, "quoted", ünïcode'))
        stamp = Header(seq=frame, stamp=Time(0, now_ns), frame_id="ultrasonic_0")
        record("ultrasonic/range_0", now_ns, Range(stamp, Range.ULTRASOUND, 0.5, 0.02, 4.0, 0.1))
        for published in sim.step(0.05):
            record(published.topic, round(published.time_s * NS_PER_S), published.message)
        pose = sim.state.pose
        record("tf", now_ns, tf_message(now_ns, pose.x, pose.y, pose.yaw, {"laser": (0, 0, 0)}))
    recorder.close()
    assert recorder.error is None
    return sent


@pytest.fixture(scope="module")
def exported(tmp_path_factory: pytest.TempPathFactory):
    out_dir = tmp_path_factory.mktemp("export")
    sent = write_recording(out_dir)
    paths = export_csv(out_dir / "recording.mcap", out_dir / "csv")
    tables = {}
    for path in paths:
        with open(path, newline="", encoding="utf-8") as handle:
            tables[path.name] = list(csv.reader(handle))
    return sent, paths, tables


def test_one_file_per_topic_named_after_it(exported) -> None:
    sent, paths, _ = exported
    assert sorted(path.name for path in paths) == sorted(csv_file_name(f"/{t}") for t in sent)
    assert "ultrasonic__range_0.csv" in {path.name for path in paths}
    assert all(path.parent.name == "csv" for path in paths)


def test_row_counts_and_times_match_the_messages(exported) -> None:
    sent, _, tables = exported
    for topic, messages in sent.items():
        rows = tables[csv_file_name(topic)][1:]
        assert len(rows) == len(messages), topic
        assert [float(row[0]) for row in rows] == [time_ns / NS_PER_S for time_ns, _ in messages]
    assert len(sent["scan"]) >= 6 and len(sent["odom"]) == 20


def test_columns_are_dotted_field_paths(exported) -> None:
    _, _, tables = exported
    assert tables["cmd_vel.csv"][0] == [
        "time_s",
        *(f"{part}.{axis}" for part in ("linear", "angular") for axis in "xyz"),
    ]
    odom = tables["odom.csv"][0]
    assert odom[:5] == ["time_s", "header.seq", "header.stamp", "header.frame_id", "child_frame_id"]
    assert "pose.pose.position.x" in odom and "pose.covariance" in odom
    assert "twist.twist.angular.z" in odom
    assert tables["scan.csv"][0][-2:] == ["ranges", "intensities"]
    assert tables["tf.csv"][0] == ["time_s", "transforms"]
    assert tables["silent.csv"] == [["time_s", "data"]]  # declared, never published


def test_values_read_back(exported) -> None:
    sent, _, tables = exported
    assert [int(row[1]) for row in tables["count.csv"][1:]] == [m.data for _, m in sent["count"]]
    assert [row[1] for row in tables["button.csv"][1:3]] == ["true", "false"]
    assert tables["note.csv"][2][1] == 'step 1, "quoted", ünïcode'
    assert tables["ultrasonic__range_0.csv"][2][2] == "0.050000000"  # header.stamp, exact
    assert tables["ultrasonic__range_0.csv"][2][5:] == ["0.5", "0.02", "4.0", "0.1"]  # float32
    twist = tables["cmd_vel.csv"][4]
    assert float(twist[1]) == pytest.approx(0.3) and float(twist[6]) == -0.5


def test_arrays_are_json_lists(exported) -> None:
    sent, _, tables = exported
    header = tables["scan.csv"][0]
    ranges_column = header.index("ranges")
    for row, (_, scan) in zip(tables["scan.csv"][1:], sent["scan"], strict=True):
        ranges = json.loads(row[ranges_column])
        assert len(ranges) == 429
        assert np.array_equal(np.float32(ranges), np.float32(scan.ranges))
    covariance_column = tables["odom.csv"][0].index("pose.covariance")
    covariance = json.loads(tables["odom.csv"][1][covariance_column])
    assert len(covariance) == 36
    transforms = json.loads(tables["tf.csv"][1][1])
    assert [t["child_frame_id"] for t in transforms] == ["base_link", "laser"]
    assert transforms[0]["header"]["frame_id"] == "map"
    rotation = sent["tf"][0][1].transforms[0].transform.rotation
    assert transforms[0]["transform"]["rotation"] == {
        "x": rotation.x,
        "y": rotation.y,
        "z": rotation.z,
        "w": rotation.w,
    }


def test_csv_file_names_are_sanitized() -> None:
    assert csv_file_name("/ultrasonic/range_0") == "ultrasonic__range_0.csv"
    assert csv_file_name("scan") == "scan.csv"
    assert csv_file_name("/../../etc/passwd") == "etc__passwd.csv"
    assert csv_file_name("/a b/c?d") == "a_b__c_d.csv"
    assert csv_file_name("/..") == csv_file_name("/") == "topic.csv"


def test_a_recording_cut_short_exports_what_it_has(tmp_path) -> None:
    recorder = Recorder(tmp_path, "cut")
    for index in range(2000):  # 4 MB: several 1 MiB chunks
        recorder.record_message("note", index * 1000, String(f"{index:05d}" + "x" * 2000))
    recorder.close()
    data = (tmp_path / "recording.mcap").read_bytes()
    (tmp_path / "cut.mcap").write_bytes(data[: len(data) * 2 // 3])
    full = export_csv(tmp_path / "recording.mcap", tmp_path / "full")
    cut = export_csv(tmp_path / "cut.mcap", tmp_path / "cut")
    full_rows = full[0].read_text().splitlines()
    cut_rows = cut[0].read_text().splitlines()
    assert len(full_rows) == 2001
    assert 1 < len(cut_rows) < len(full_rows)
    assert cut_rows == full_rows[: len(cut_rows)]


def test_non_ros1_recordings_are_refused_with_the_topic_named(tmp_path) -> None:
    path = tmp_path / "json.mcap"
    with open(path, "wb") as stream:
        writer = Writer(stream)
        writer.start()
        schema = writer.register_schema("Thing", "jsonschema", b"{}")
        channel = writer.register_channel("/things", "json", schema)
        writer.add_message(channel, 0, b"{}", 0)
        writer.finish()
    with pytest.raises(ValueError, match="'/things' is not ROS1-encoded"):
        export_csv(path, tmp_path / "csv")
    with pytest.raises(FileNotFoundError, match="no recording"):
        export_csv(tmp_path / "missing.mcap", tmp_path / "csv")


def test_every_registered_type_flattens() -> None:
    for cls in MESSAGE_TYPES.values():
        columns = _columns(cls)
        row = _row(cls(), columns)
        assert len(row) == len(columns) and all(isinstance(value, str) for value in row)
