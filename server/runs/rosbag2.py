"""What rosbag2 writes around a ROS 2 recording, so `ros2 bag info` and `ros2 bag play` take ours.

A ROS 2 run's `recording.mcap` is written as rosbag2's MCAP storage plugin writes it (ros2/rosbag2,
rosbag2_storage_mcap/src/mcap_storage.cpp, metadata version 9 as in Jazzy):

- header profile "ros2"; one schema per type, named "pkg/msg/Name", encoding "ros2msg", data the
  type's full definition (the class's `_full_text`); one channel per topic ("/scan"), message
  encoding "cdr", channel metadata `offered_qos_profiles` (a YAML list of the publishers' QoS,
  rosbag2_storage/src/rosbag2_storage/qos.cpp: string enum names, durations as {sec, nsec}) and
  `topic_type_hash` (left empty: we do not compute RIHS01 hashes; rosbag2 reads an empty one);
- a metadata record named "rosbag2" whose `serialized_metadata` is the bag's metadata document,
  written just before the summary, as `update_metadata` does at close;
- `metadata.yaml` beside it (rosbag2_storage/metadata_io.cpp): `ros2 bag play FILE.mcap` reads a
  single file without it, but `ros2 bag play DIR` and rosbags' reader need it.

QoS: what a ROS 2 recorder sees through discovery - history unknown with depth 0 (DDS does not
announce them), reliable, volatile, infinite deadline, lifespan and lease - except `map`, which
the map server offers transient-local (a late subscriber still gets it), as Nav2's does.

Our internal service topics (`__srv__/<service>`, `__srv__reply/<node>`: a service's calls, as a
rosbag2 recording keeps a service's traffic) are written like every other topic, as
robodojo_msgs/msg/ServiceCall and ServiceReply with their ros2msg schemas: readers decode them
from the schema (rosbags, mcap-ros2-support), and `ros2 bag play`, which has no robodojo_msgs
package, warns "Ignoring a topic" and plays the rest. Action topics (`.../_action/status`) are
ordinary ROS 2 messages, written as rosbag2 writes them with `--include-hidden-topics`.
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path

import yaml

METADATA_FILE = "metadata.yaml"
METADATA_RECORD = "rosbag2"  # the MCAP metadata record rosbag2 reads back
METADATA_VERSION = 9  # rosbag2_storage BagMetadata::version in Jazzy
ROS_DISTRO = "jazzy"  # the distribution whose message definitions we carry (sandbox.msgs2)
_INFINITE = {"sec": 9223372036, "nsec": 854775807}  # RMW_DURATION_INFINITE as discovery reports it
TRANSIENT_LOCAL_TOPICS = ("map",)  # latched for late subscribers, as Nav2's map_server offers it


def offered_qos(topic: str) -> list[dict]:
    """The QoS profiles (one publisher's) rosbag2 would record for `topic`."""
    durability = "transient_local" if topic.lstrip("/") in TRANSIENT_LOCAL_TOPICS else "volatile"
    return [
        {
            "history": "unknown",
            "depth": 0,
            "reliability": "reliable",
            "durability": durability,
            "deadline": dict(_INFINITE),
            "lifespan": dict(_INFINITE),
            "liveliness": "automatic",
            "liveliness_lease_duration": dict(_INFINITE),
            "avoid_ros_namespace_conventions": False,
        }
    ]


def channel_metadata(topic: str) -> dict[str, str]:
    """The metadata of an MCAP channel, as rosbag2's MCAP storage writes it."""
    profiles = yaml.safe_dump(offered_qos(topic), sort_keys=False, default_flow_style=False)
    return {"offered_qos_profiles": profiles.rstrip("\n"), "topic_type_hash": ""}


def bag_metadata(
    file_name: str,
    topics: Iterable[tuple[str, str, int]],
    start_ns: int,
    end_ns: int,
) -> dict:
    """The `rosbag2_bagfile_information` document: `topics` is (MCAP topic, type, message
    count); `start_ns`/`end_ns` the first and last log times [ns]."""
    topic_list = list(topics)
    count = sum(n for _, _, n in topic_list)
    duration = {"nanoseconds": max(0, end_ns - start_ns)}
    starting_time = {"nanoseconds_since_epoch": start_ns}
    return {
        "version": METADATA_VERSION,
        "storage_identifier": "mcap",
        "duration": duration,
        "starting_time": starting_time,
        "message_count": count,
        "topics_with_message_count": [
            {
                "topic_metadata": {
                    "name": name,
                    "type": type_name,
                    "serialization_format": "cdr",
                    "offered_qos_profiles": offered_qos(name),
                    "type_description_hash": "",
                },
                "message_count": n,
            }
            for name, type_name, n in topic_list
        ],
        "compression_format": "",
        "compression_mode": "",
        "relative_file_paths": [file_name],
        "files": [
            {
                "path": file_name,
                "starting_time": starting_time,
                "duration": duration,
                "message_count": count,
            }
        ],
        "custom_data": None,
        "ros_distro": ROS_DISTRO,
    }


class _PlainDumper(yaml.SafeDumper):
    """YAML without anchors and aliases: the document shares dicts (start time, duration),
    which PyYAML would write as `&id001`/`*id001`; rosbag2 writes every value out."""

    def ignore_aliases(self, data: object) -> bool:
        return True


def serialized(metadata: dict) -> str:
    """The document as the "rosbag2" MCAP metadata record carries it (YAML, no outer key)."""
    return yaml.dump(metadata, Dumper=_PlainDumper, sort_keys=False)


def write_metadata_yaml(out_dir: Path, metadata: dict) -> Path:
    """`metadata.yaml` beside the MCAP file, as rosbag2's MetadataIo writes it."""
    path = Path(out_dir) / METADATA_FILE
    document = {"rosbag2_bagfile_information": metadata}
    path.write_text(yaml.dump(document, Dumper=_PlainDumper, sort_keys=False), encoding="utf-8")
    return path
