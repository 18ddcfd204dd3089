"""A ROS 2 run's recording, as `ros2 bag record` writes MCAP (server/runs/rosbag2.py), read by
independent readers (rosbags' AnyReader through metadata.yaml, mcap-ros2-support on the file)
and by ours: CSV export, the exercise evidence (ROS 1 objects for the checks), the 3D view's
replay. The run is driven through the engine without a sandboxed node (tests/runs/
test_ros2_edge.py explains how); real rclpy runs are in tests/runs/test_ros2_runs.py."""

from __future__ import annotations

import csv
import math
from pathlib import Path
from types import SimpleNamespace

import pytest
import yaml
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
from rosbags.highlevel import AnyReader

from sandbox.msgs import get_message_class
from sandbox.protocol import Envelope
from server.exercises.evidence import load_evidence
from server.runs.export import export_csv
from server.runs.result import RunResult
from server.runs.run import Run
from server.runs.spec import NodeSpec, RunSpec
from server.runs.state import RunState
from server.viz.recording import load_recording

NS = 1_000_000_000


def decoded_messages(path: str) -> list:
    """Every message of an MCAP file as mcap-ros2-support decodes it (an independent reader)."""
    with open(path, "rb") as handle:
        reader = make_reader(handle, decoder_factories=[DecoderFactory()])
        return [
            SimpleNamespace(channel=channel, schema=schema, ros_msg=decoded)
            for schema, channel, _, decoded in reader.iter_decoded_messages()
        ]


@pytest.fixture(scope="module")
def recorded(tmp_path_factory) -> tuple[Run, dict[str, str]]:
    """Three seconds of a TurtleBot3 in a ROS 2 run, with built-ins, a goal, a service call on
    the bus and a node's TwistStamped commands."""
    out = tmp_path_factory.mktemp("ros2_run")
    spec = RunSpec(
        robot="turtlebot3",
        world="office",
        nodes=(NodeSpec("driver", "import rclpy\n", "driver.py"),),
        builtin_nodes=("map_server", "localization", "planner"),
        goal=(1.0, 0.0, 0.0),
    )
    run = Run(spec, launcher=None, out_dir=out)
    run.core.prepare()
    run.bus.add_node("driver")
    run.builtins.start(run.core)
    stamped = get_message_class("geometry_msgs/msg/TwistStamped")()
    stamped.twist.linear.x, stamped.twist.angular.z = 0.1, 0.2
    call = get_message_class("robodojo_msgs/msg/ServiceCall")(service="s", reply_to="r", id=1)
    for step in range(1, 31):
        run.core.advance_to(step * NS // 10)
        run.core.from_node(
            run.slots["driver"],
            [Envelope("cmd_vel", stamped._type, stamped.serialize())]
            + ([Envelope("__srv__/s", call._type, call.serialize())] if step == 5 else []),
        )
    run.core.edge.command_zero(run.time_ns)
    run.recorder.write_json("metrics", run.metrics())
    return run, run.recorder.close()


def test_the_file_is_what_rosbag2_writes(recorded):
    _, paths = recorded
    with open(paths["recording"], "rb") as handle:
        reader = make_reader(handle)
        assert reader.get_header().profile == "ros2"
        summary = reader.get_summary()
        metadata = {record.name: record.metadata for record in reader.iter_metadata()}
    schemas = {schema.name: schema for schema in summary.schemas.values()}
    assert {schema.encoding for schema in schemas.values()} == {"ros2msg"}
    scan_text = schemas["sensor_msgs/msg/LaserScan"].data.decode()
    assert "builtin_interfaces/Time stamp" in scan_text  # the nested definitions come along
    for channel in summary.channels.values():
        assert channel.message_encoding == "cdr"
        assert set(channel.metadata) == {"offered_qos_profiles", "topic_type_hash"}
        profile = yaml.safe_load(channel.metadata["offered_qos_profiles"])[0]
        assert profile["reliability"] == "reliable"
        assert profile["deadline"] == {"sec": 9223372036, "nsec": 854775807}
    topics = {channel.topic for channel in summary.channels.values()}
    assert {"/scan", "/odom", "/imu", "/cmd_vel", "/tf", "/goal", "/map", "/pose"} <= topics
    assert "/__srv__/s" in topics  # a service's calls, decodable from their schema
    inside = yaml.safe_load(metadata["rosbag2"]["serialized_metadata"])
    assert inside["version"] == 9 and inside["storage_identifier"] == "mcap"
    assert metadata["run"]["ros_version"] == "2"


def test_metadata_yaml_counts_every_message(recorded):
    _, paths = recorded
    text = Path(paths["metadata"]).read_text()
    assert "&id" not in text and "*id" not in text  # every value written out, as rosbag2 does
    document = yaml.safe_load(text)["rosbag2_bagfile_information"]
    assert document["relative_file_paths"] == ["recording.mcap"]
    with open(paths["recording"], "rb") as handle:
        statistics = make_reader(handle).get_summary().statistics
    assert document["message_count"] == statistics.message_count
    counts = {
        t["topic_metadata"]["name"]: t["message_count"]
        for t in document["topics_with_message_count"]
    }
    assert counts["/cmd_vel"] == 31  # thirty commands and the zero at the end
    assert counts["/map"] == 1
    assert document["duration"]["nanoseconds"] == 3 * NS


def test_rosbags_reads_the_bag_directory_and_decodes_every_message(recorded):
    run, _ = recorded
    with AnyReader([run.out_dir]) as reader:
        assert reader.duration == 3 * NS + 1
        decoded = 0
        for connection, _, raw in reader.messages():
            message = reader.deserialize(raw, connection.msgtype)
            decoded += 1
            if connection.topic == "/cmd_vel":
                assert connection.msgtype == "geometry_msgs/msg/TwistStamped"
        assert decoded == reader.message_count
    assert decoded > 100
    assert message is not None


def test_mcap_ros2_decodes_every_message_of_the_file(recorded):
    _, paths = recorded
    seen = {}
    for item in decoded_messages(paths["recording"]):
        seen[item.channel.topic] = item.ros_msg
    assert seen["/scan"].range_max > 0
    assert seen["/tf"].transforms[0].child_frame_id == "base_link"
    assert seen["/goal"].pose.position.x == 1.0
    assert (seen["/__srv__/s"].service, seen["/__srv__/s"].id) == ("s", 1)


def test_csv_export_has_ros2_field_names(recorded, tmp_path):
    _, paths = recorded
    files = {path.name: path for path in export_csv(Path(paths["recording"]), tmp_path)}
    with open(files["cmd_vel.csv"], newline="") as handle:
        rows = list(csv.reader(handle))
    assert rows[0][:4] == ["time_s", "header.stamp.sec", "header.stamp.nanosec", "header.frame_id"]
    assert rows[1][rows[0].index("twist.linear.x")] == "0.1"
    with open(files["scan.csv"], newline="") as handle:
        header = next(csv.reader(handle))
    assert "ranges" in header and "header.stamp.nanosec" in header


def test_evidence_gives_the_checks_ros1_objects(recorded):
    run, _ = recorded
    result = RunResult(run.run_id, RunState.FINISHED, "", 3.0, 0.0, {}, {}, {}, {}, 2)
    evidence = load_evidence(result, run.out_dir)
    time_s, odom = evidence.series("odom")[-1]
    assert odom._type == "nav_msgs/Odometry"  # ROS 1, as every check is written
    assert odom.header.stamp.to_sec() == pytest.approx(time_s)
    commands = evidence.series("cmd_vel")
    assert commands[0][1]._type == "geometry_msgs/TwistStamped"
    assert len(evidence.pose_t) == 30  # /tf at each of the thirty 0.1 s steps (30 Hz is slower)
    assert evidence.pose_x[-1] == pytest.approx(run.sim.state.pose.x, abs=0.01)
    assert math.isfinite(evidence.pose_yaw[-1])


def test_the_3d_view_replays_a_ros2_recording(recorded):
    run, paths = recorded
    recording = load_recording(paths["recording"])
    state = recording.state_at(3.0)
    assert state.pose[0] == pytest.approx(run.sim.state.pose.x, abs=0.01)
    assert state.goal == (1.0, 0.0, 0.0)
    assert state.latest["scan"][0] == "sensor_msgs/LaserScan"
