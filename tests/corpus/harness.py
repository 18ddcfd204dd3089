"""Drive a corpus case through the real run engine and read back what it left: the run's
state, the recording (every topic, and the true pose on ``/tf``), the nodes' logs, their
artifacts, the topic graph and the metrics.

Two ways in, both the real thing: ``server.runs.run.Run`` with the real sandbox launcher for
scripts, and the ``robodojo run`` command line for launch files (as a student types it). Either
way everything a check reads comes from the run's output folder, so one check serves both.

A ROS 2 run's recording is read back with mcap-ros2-support, which decodes each CDR message
from the ``ros2msg`` schema stored beside it (as ``ros2 bag play`` would), not with our own
classes: a check on a ROS 2 recording is also a check that other tools can read it.
"""

from __future__ import annotations

import json
import math
import struct
import subprocess
import sys
from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path

from mcap.reader import make_reader
from mcap_ros2._vendor.rosidl_adapter.parser import InvalidResourceName
from mcap_ros2.decoder import DecoderFactory

from sandbox.msgs import get_message_class
from sandbox.protocol import Clock
from server.runs.run import Run
from server.runs.spec import NodeSpec, RunSpec

SCRIPTS = Path(__file__).parent / "scripts"  # ROS 1 (rospy) scripts and launch files
SCRIPTS_ROS2 = Path(__file__).parent / "scripts_ros2"  # ROS 2 (rclpy): a package's layout
REPO = Path(__file__).parents[2]
NS = 1_000_000_000
WORLD_FRAME = "map"
BODY_FRAMES = ("base_link", "base_footprint")  # the robot's body in the recording's /tf
CLI_TIMEOUT_S = 120.0  # [s] a launch-file run of a few seconds plus its sandbox start-up


@dataclass(frozen=True)
class Node:
    """One script of a case, with what rosrun or a launch file would give it."""

    file: str
    name: str | None = None
    params: dict[str, object] = field(default_factory=dict)
    remaps: tuple[tuple[str, str], ...] = ()
    args: tuple[str, ...] = ()

    @property
    def node_name(self) -> str:
        return self.name or Path(self.file).stem


@dataclass(frozen=True)
class Pose:
    t: float  # [s] run time
    x: float  # [m] world frame
    y: float  # [m]
    yaw: float  # [rad] counter-clockwise from +x


@dataclass
class Outcome:
    """What a run left behind, read from its output folder."""

    state: str
    reason: str
    out_dir: Path
    clock: Clock

    @cached_property
    def recording(self) -> dict[str, list[tuple[float, object]]]:
        """Topic (without its leading /) -> [(time [s], message)] in recording order. ROS 1
        messages are decoded by our classes, ROS 2 (CDR) ones by mcap-ros2-support from the
        recorded schema."""
        topics: dict[str, list[tuple[float, object]]] = {}
        ros2 = DecoderFactory()
        decoders: dict[int, Callable[[bytes], object]] = {}
        with open(self.out_dir / "recording.mcap", "rb") as f:
            for schema, channel, message in make_reader(f).iter_messages():
                decode = decoders.get(channel.id)
                if decode is None:
                    try:
                        decode = ros2.decoder_for(channel.message_encoding, schema)
                    except InvalidResourceName:
                        # mcap-ros2-support refuses an action's own types (a name such as
                        # Fibonacci_FeedbackMessage is not a .msg name), in rosbag2's
                        # recordings too: those few are decoded by our classes.
                        decode = None
                    if decode is None:
                        decode = get_message_class(schema.name).deserialize
                    decoders[channel.id] = decode
                topics.setdefault(channel.topic.lstrip("/"), []).append(
                    (message.log_time / NS, decode(message.data))
                )
        return topics

    @cached_property
    def recording_format(self) -> tuple[str, set[tuple[str, str]]]:
        """The recording's profile and its (schema encoding, message encoding) pairs."""
        with open(self.out_dir / "recording.mcap", "rb") as f:
            reader = make_reader(f)
            profile = reader.get_header().profile
            summary = reader.get_summary()
        assert summary is not None, "the recording has no summary section"
        encodings = {
            (summary.schemas[channel.schema_id].encoding, channel.message_encoding)
            for channel in summary.channels.values()
        }
        return profile, encodings

    def messages(self, topic: str) -> list[tuple[float, object]]:
        return self.recording.get(topic.lstrip("/"), [])

    @cached_property
    def poses(self) -> list[Pose]:
        """The robot's true pose over the run, from the recording's map -> body transform."""
        poses = []
        for time_s, tf in self.messages("tf"):
            for transform in tf.transforms:
                if (
                    transform.header.frame_id == WORLD_FRAME
                    and transform.child_frame_id in BODY_FRAMES
                ):
                    q = transform.transform.rotation
                    yaw = math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))
                    t = transform.transform.translation
                    poses.append(Pose(time_s, t.x, t.y, yaw))
                    break
        assert poses, f"the recording has no {WORLD_FRAME} -> body transform on /tf"
        return poses

    def pose_at(self, time_s: float) -> Pose:
        """The recorded pose nearest to `time_s`."""
        return min(self.poses, key=lambda pose: abs(pose.t - time_s))

    @property
    def start(self) -> Pose:
        return self.poses[0]

    @property
    def end(self) -> Pose:
        return self.poses[-1]

    def travelled_between(self, t0: float, t1: float) -> float:
        """Straight-line distance [m] between the poses at t0 and t1."""
        a, b = self.pose_at(t0), self.pose_at(t1)
        return math.hypot(b.x - a.x, b.y - a.y)

    def turned(self) -> float:
        """Total signed heading change [rad] over the run, unwrapped."""
        total = 0.0
        for a, b in zip(self.poses, self.poses[1:], strict=False):
            total += math.atan2(math.sin(b.yaw - a.yaw), math.cos(b.yaw - a.yaw))
        return total

    def log(self, node: str) -> str:
        path = self.out_dir / "logs" / f"{node}.log"
        return path.read_text() if path.is_file() else ""

    @cached_property
    def logs(self) -> dict[str, str]:
        folder = self.out_dir / "logs"
        return {p.stem: p.read_text() for p in folder.glob("*.log")} if folder.is_dir() else {}

    def artifact(self, node: str, name: str) -> Path:
        return self.out_dir / "artifacts" / node / name

    @cached_property
    def metrics(self) -> dict:
        return json.loads((self.out_dir / "metrics.json").read_text())

    @cached_property
    def graph(self) -> dict[str, dict]:
        """Topic name (without its leading /) -> publishers, subscribers, messages, rate."""
        document = json.loads((self.out_dir / "graph.json").read_text())
        return {topic["name"].lstrip("/"): topic for topic in document["topics"]}

    def describe(self) -> str:
        """The run's end and every log's tail, for an assertion message."""
        tails = {name: text.splitlines()[-12:] for name, text in self.logs.items()}
        return f"{self.state}: {self.reason}; logs: {json.dumps(tails, indent=1)}"


def png_size(path: Path) -> tuple[int, int]:
    """(width, height) [px] from a PNG's IHDR chunk."""
    data = path.read_bytes()[:24]
    assert data[:8] == b"\x89PNG\r\n\x1a\n", f"{path.name} is not a PNG"
    return struct.unpack(">II", data[16:24])


def run_scripts(
    launcher,
    out_dir: Path,
    *,
    robot: str,
    world: str,
    nodes: tuple[Node, ...],
    clock: Clock,
    duration_s: float,
    spawn: str | None = None,
    initial_pose: tuple[float, float, float] | None = None,
    files: tuple[str, ...] = (),
    builtin_nodes: tuple[str, ...] = (),
    seed: int = 1,
    scripts: Path = SCRIPTS,
) -> Outcome:
    """Run the scripts of folder `scripts` unchanged as nodes of one run
    (server.runs.run.Run)."""
    specs = []
    for node in nodes:
        # Only what a case uses is passed, so a case without parameters or remappings runs on
        # an engine that does not have them yet.
        extra = {}
        if node.params:
            extra["params"] = dict(node.params)
        if node.remaps:
            extra["remaps"] = node.remaps
        if node.args:
            extra["args"] = node.args
        path = scripts / node.file
        specs.append(
            NodeSpec(
                name=node.node_name,
                code=path.read_text(encoding="utf-8"),
                filename=path.name,
                **extra,
            )
        )
    options: dict[str, object] = {}
    if files:
        options["files"] = tuple((name, (scripts / name).read_bytes()) for name in files)
    if builtin_nodes:
        options["builtin_nodes"] = builtin_nodes
    spec = RunSpec(
        robot=robot,
        world=world,
        nodes=tuple(specs),
        clock=clock,
        duration_s=duration_s,
        seed=seed,
        spawn=spawn,
        initial_pose=initial_pose,
        **options,
    )
    result = Run(spec, launcher, out_dir).execute()
    return Outcome(str(result.state), result.reason, out_dir, clock)


def run_launch_file(
    out_dir: Path,
    *,
    launch: str,
    launch_args: tuple[str, ...] = (),
    robot: str,
    world: str,
    clock: Clock,
    duration_s: float,
    spawn: str | None = None,
    seed: int = 1,
    scripts: Path = SCRIPTS,
) -> Outcome:
    """Run a launch file of folder `scripts` as a student would:
    `robodojo run --launch FILE [name:=value ...]`."""
    command = [
        sys.executable,
        "-m",
        "server.cli",
        "run",
        "--robot",
        robot,
        "--world",
        world,
        "--launch",
        str(scripts / launch),
        *launch_args,
        "--clock",
        clock.value,
        "--duration",
        str(duration_s),
        "--seed",
        str(seed),
        "--out",
        str(out_dir),
    ]
    if spawn:
        command += ["--spawn", spawn]
    done = subprocess.run(
        command, cwd=REPO, capture_output=True, text=True, timeout=CLI_TIMEOUT_S, check=False
    )
    lines = done.stdout.strip().splitlines()
    assert lines, f"robodojo run printed nothing (exit {done.returncode}): {done.stderr.strip()}"
    try:
        summary = json.loads(lines[-1])
    except json.JSONDecodeError:
        raise AssertionError(
            f"robodojo run did not end with its JSON summary: {done.stdout[-500:]}"
            f"{done.stderr[-1500:]}"
        ) from None
    return Outcome(summary["state"], summary["reason"], out_dir, clock)


# ------------------------------------------------------------------------------------- cases
@dataclass(frozen=True)
class Case:
    """One corpus run: its scripts (or launch file), where it runs and what it must do."""

    id: str
    robot: str
    world: str
    duration_s: float
    check: Callable[[Outcome], None]
    nodes: tuple[Node, ...] = ()
    launch: str | None = None  # relative to `scripts`
    launch_args: tuple[str, ...] = ()  # name:=value, as roslaunch and ros2 launch take them
    spawn: str | None = None
    initial_pose: tuple[float, float, float] | None = None  # x [m], y [m], yaw [rad]
    files: tuple[str, ...] = ()  # workspace data files the scripts read
    builtin_nodes: tuple[str, ...] = ()  # the run's trusted helpers (map_server, ...)
    clocks: tuple[Clock, ...] = (Clock.LOCKSTEP, Clock.REALTIME)
    needs: tuple[str, ...] = ()  # features not on main yet: strict xfail on both clocks
    realtime_needs: tuple[str, ...] = ()  # ... on the realtime clock only
    scripts: Path = SCRIPTS  # the folder the scripts come from (the workspace)


def run_case(case: Case, clock: Clock, launcher, out_dir: Path) -> Outcome:
    if case.launch:
        return run_launch_file(
            out_dir,
            launch=case.launch,
            launch_args=case.launch_args,
            robot=case.robot,
            world=case.world,
            clock=clock,
            duration_s=case.duration_s,
            spawn=case.spawn,
            scripts=case.scripts,
        )
    return run_scripts(
        launcher,
        out_dir,
        robot=case.robot,
        world=case.world,
        nodes=case.nodes,
        clock=clock,
        duration_s=case.duration_s,
        spawn=case.spawn,
        initial_pose=case.initial_pose,
        files=case.files,
        builtin_nodes=case.builtin_nodes,
        scripts=case.scripts,
    )


def start_realtime_runs(
    cases: list[Case], launcher, out_dir: Callable[[str], Path], at_once: int
) -> tuple[ThreadPoolExecutor, dict[str, Future[Outcome]]]:
    """Start the realtime runs of `cases`, `at_once` at a time: a realtime run takes its
    duration in wall time, mostly waiting, so they overlap while each test waits for its own."""
    pool = ThreadPoolExecutor(max_workers=at_once, thread_name_prefix="corpus")
    futures = {
        case.id: pool.submit(run_case, case, Clock.REALTIME, launcher, out_dir(case.id))
        for case in cases
    }
    return pool, futures
