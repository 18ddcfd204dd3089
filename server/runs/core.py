"""The run engine's core: the lifecycle of one run (start the nodes, run a clock, finish with a
result) and the routing between its nodes, its built-ins and its robot. It starts no thread and
writes nowhere itself: what leaves the run goes to the sinks it is given (server/runs/outputs.py),
commands wait in its inbox (server/runs/inbox.py) until its clock takes them, and the clock that
drives it (server/runs/clocks.py) sees only the narrow `ClockedRun` side of it:

    due_nodes(now_ns)             the sleeping nodes to wake now, in launch-file order
    next_event_ns(every_publication=...)   when something next happens
    advance_to(time_ns)           step the robot there and route what it published
    tick_s, apply_commands(), wake(slot, now_ns), begin_wake(...), collect_replies(), ...

Its parts: the sandboxed nodes (node_host.py), the built-ins (builtin_host.py; each is handed
this core as its `run`), the robot's edge (robot_edge.py), the topic bus (bus.py). Nothing that
goes wrong in one run escapes `run()`: a node that raises or is killed, a recorder that fails, a
simulator that raises - each ends this run with a reason and leaves others alone.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable
from pathlib import Path

import sandbox.services  # noqa: F401  # registers the service envelope types the recorder sees
from sandbox.launcher import Launcher
from sandbox.protocol import Envelope, NodeInfo, RobotTopic
from sandbox.units import NS_PER_S
from server.runs import controls
from server.runs.builtin_host import BuiltinHost
from server.runs.bus import TopicBus
from server.runs.dialect import Dialect
from server.runs.faults import Faults
from server.runs.inbox import CommandInbox
from server.runs.node_host import NodeHost
from server.runs.outputs import RecordingSink, RunOutputs
from server.runs.recorder import Recorder
from server.runs.result import RunEnd, RunResult
from server.runs.robot_edge import RobotEdge
from server.runs.slots import NodeSlot
from server.runs.spec import NodeSpec, RunSpec
from server.runs.state import RunState, check_transition
from server.sim import Pose2D, Simulation
from server.sim.backend import RobotBackend
from server.sim.simulation import EventKind, SimulationError

log = logging.getLogger("robodojo.runs")


class RunCore:
    def __init__(
        self,
        spec: RunSpec,
        launcher: Launcher,
        out_dir: Path,
        run_id: str,
        outputs: RunOutputs,
        backend: RobotBackend | None = None,
    ) -> None:
        self.spec = spec
        self.launcher = launcher
        self.out_dir = out_dir
        self.run_id = run_id
        self.outputs = outputs
        self.dialect = Dialect(spec.ros_version)  # the robot's edge in the run's ROS dialect
        self.real_robot = backend is not None
        self._given_backend = backend
        self.sim: RobotBackend | None = None  # the robot driven: `backend`, else a Simulation
        self.edge: RobotEdge | None = None
        self.recorder: Recorder | None = None
        self.state = RunState.CREATED
        self.reason = ""
        self.time_ns = 0
        self.duration_ns = round(spec.duration_s * NS_PER_S)
        self.clock_wall_s = 0.0  # wall time the clock ran (node start-up excluded)
        self._state_lock = threading.Lock()
        self.inbox = CommandInbox()
        self.faults = Faults()
        self.bus = TopicBus()
        self.nodes = NodeHost(spec.nodes, self.bus, outputs, self.from_node)
        self.slots = self.nodes.slots
        self.builtins = BuiltinHost(spec.builtin_nodes, self.dialect.ros_version)
        self._script = [  # (run time [ns], command), soonest first
            (round(at_s * NS_PER_S), command)
            for at_s, command in sorted(spec.script, key=lambda event: event[0])
        ]

    @property
    def time_s(self) -> float:
        return self.time_ns / NS_PER_S

    @property
    def velocity_topic(self) -> str | None:
        """The robot's Twist command topic (Control, cmd_vel), if it has one."""
        return self.edge.velocity_topic

    # ----------------------------------------------------------------------------- lifecycle
    def move(self, new: RunState) -> None:
        with self._state_lock:
            check_transition(self.state, new)
            self.state = new
        self.outputs.state(new, self.reason, self.time_ns / NS_PER_S)

    def run(self, clock: Callable[[RunCore], None]) -> RunResult:
        """Start, let `clock` drive the run to its end, finish; return the result. Never raises
        for anything a node does."""
        wall_start = time.monotonic()
        end_state, reason = RunState.FAILED, "failed: the run did not start"
        self.move(RunState.STARTING)
        try:
            self.prepare()
            self.start_nodes()
            self.move(RunState.RUNNING)
            clock_started = time.monotonic()
            try:
                clock(self)
            finally:
                self.clock_wall_s = time.monotonic() - clock_started
            end_state, reason = RunState.FINISHED, "finished: duration reached"
        except RunEnd as end:
            end_state, reason = end.state, end.reason
        except Exception as error:  # a fault of ours must end this run, not the server
            log.exception("run %s failed inside the engine", self.run_id)
            end_state, reason = RunState.FAILED, f"failed: internal error ({error!r})"
        if self.state is not RunState.STOPPING:
            self.move(RunState.STOPPING)
        return self.finish(end_state, reason, time.monotonic() - wall_start)

    def prepare(self) -> None:
        """The robot, the recording, the run's topics and the messages of time 0."""
        spec = self.spec
        spawn = Pose2D(*spec.initial_pose) if spec.initial_pose else spec.spawn
        self.sim = self._given_backend or Simulation(
            spec.robot, spec.world, seed=spec.seed, spawn=spawn
        )
        self.out_dir.mkdir(parents=True, exist_ok=True)
        dialect = self.dialect
        self.recorder = Recorder(
            self.out_dir,
            self.run_id,
            profile="ros2" if dialect.ros2 else "ros1",
            metadata={
                "ros_version": str(dialect.ros_version),
                "robot": spec.robot,
                "world": spec.world,
                "clock": str(spec.clock),
                "seed": str(spec.seed),
                "duration_s": str(spec.duration_s),
                "nodes": ",".join(node.name for node in spec.nodes),
            },
        )
        self.outputs.add(RecordingSink(self.recorder), first=True)
        self.edge = RobotEdge(self.sim, dialect, self.bus, self.outputs, self.faults, self.run_id)
        self.edge.declare(self.recorder)
        self.sim.note_readers(self.bus.has_subscribers)  # a silent real robot names these first
        if spec.light_position is not None:
            movable = [light.name for light in self.sim.lights if light.movable]
            if movable:
                self.sim.move_light(movable[0], *spec.light_position)
        for published in self.sim.reset():
            self.edge.from_robot(published.topic, published.message, 0.0, self.time_ns)
        if spec.goal is not None:
            self.edge.publish_goal(*spec.goal, self.time_ns)

    def node_info(self, node: NodeSpec) -> NodeInfo:
        topics = self.edge.topics_for_nodes()
        topics.extend(
            RobotTopic(topic, kind, "publish", rate)
            for topic, kind, rate in self.builtins.published_topics(self)
        )
        return NodeInfo(
            node_name=node.name,
            robot=self.spec.robot,
            robot_topics=topics,
            velocity_topic=self.velocity_topic,
            clock=self.spec.clock,
            start_time_s=0.0,
            params={**self.spec.params, **node.params},
            argv=list(node.args),
            remaps=dict(node.remaps),
            namespace=node.namespace,
            ros_version=self.dialect.ros_version,
        )

    def start_nodes(self) -> None:
        self.nodes.start(self.launcher, self.node_info, self.spec.files)
        self.builtins.start(self)

    def finish(self, end_state: RunState, reason: str, wall_s: float) -> RunResult:
        """Stop the robot, end every node, close the recording; the run's last state."""
        if self.edge is not None and self.recorder is not None:
            self.edge.command_zero(self.time_ns)
        end_state, reason = self.nodes.end_all(end_state, reason, self.recorder)
        if self.recorder is not None:
            metrics = self.metrics()
            self.recorder.write_json("metrics", metrics)
            self.recorder.write_json("graph", self.bus.graph())
            paths = self.recorder.close()
            # Checked after close: the last batch (or the summary) may be what failed.
            if self.recorder.error and end_state is RunState.FINISHED:
                end_state, reason = RunState.FAILED, f"failed: {self.recorder.error}"
        else:
            metrics, paths = self.metrics(), {}
        self.reason = reason
        self.inbox.close()
        self.move(end_state)
        return RunResult(
            run_id=self.run_id,
            state=end_state,
            reason=reason,
            duration_s=self.time_ns / NS_PER_S,
            wall_s=wall_s,
            metrics=metrics["run"],
            nodes=metrics["nodes"],
            paths=paths,
            graph=self.bus.graph(),
            ros_version=self.dialect.ros_version,
        )

    def metrics(self) -> dict:
        state = self.sim.state if self.sim is not None else None
        run = {
            "collisions": state.contact_count if state else 0,
            "distance_travelled_m": state.distance_travelled_m if state else 0.0,
            "time_out_of_bounds_s": state.time_out_of_bounds_s if state else 0.0,
            "clock_wall_s": self.clock_wall_s,
            "ros_version": self.dialect.ros_version,
        }
        return {"run": run, "nodes": self.nodes.metrics()}

    # ----------------------------------------------------------------------------- routing
    def route(
        self,
        source: str,
        envelope: Envelope,
        message: object | None = None,
        native: bool = False,
        sender: NodeSlot | None = None,
    ) -> None:
        """The one path of a message published inside the run, by a sandboxed node or a
        built-in: onto the bus, into the outputs, into the robot if the topic is one of its
        commands, to the built-ins that listen. `sender`: the sandboxed node that sent it (not
        trusted: a command it gets wrong is refused with a line in its log); None for a
        built-in (trusted). `message`: the decoded object when the publisher has one (a
        built-in's; a ROS 2 object if `native`), else decoded here only if a built-in listens."""
        now_ns = self.time_ns
        topic = envelope.topic
        self.bus.publish(source, envelope, now_ns / NS_PER_S)
        self.outputs.record(topic, envelope.type, now_ns, envelope.data)
        if topic in self.edge.commands:
            if sender is not None:
                self.edge.command_from_node(sender, envelope, now_ns)
            else:
                self.edge.command_trusted(topic, message, native)
        if self.builtins and self.builtins.listens_to(topic):
            if message is None:
                message, native = self.dialect.decode(envelope), self.dialect.ros2
            self.builtins.deliver(self, source, topic, message, native)

    def from_node(self, slot: NodeSlot, published: list[Envelope]) -> None:
        for envelope in published:
            slot.metrics.published += 1
            self.route(slot.name, envelope, sender=slot)

    # ----------------------------------------------------------------------------- the clocks' side
    @property
    def tick_s(self) -> float:
        """[s] the robot's smallest step: a lockstep clock moves on by at least this."""
        return self.sim.tick_s

    @property
    def paused(self) -> bool:
        return self.state is RunState.PAUSED

    @property
    def command_fd(self) -> int:
        """Readable while a command waits in the inbox (a sleeping realtime loop selects it)."""
        return self.inbox.fd

    def apply_commands(self) -> None:
        """Take and apply the commands waiting in the inbox (Stop raises RunEnd)."""
        for command in self.inbox.take_all():
            controls.apply(self, command)

    def wait_for_command(self, timeout_s: float) -> None:
        """Block up to `timeout_s` [s] for one command and apply it (a paused lockstep loop)."""
        command = self.inbox.wait(timeout_s)
        if command is not None:
            controls.apply(self, command)

    def due_nodes(self, now_ns: int) -> list[NodeSlot]:
        """The sleeping nodes to wake at `now_ns`, in launch-file order."""
        return self.nodes.due(now_ns)

    def next_event_ns(self, *, every_publication: bool) -> int:
        """Run time [ns] of the next thing to happen: the end, a scripted command, a built-in's
        tick, /tf for a listener, a sleeping node's wake time, the robot's next publication.
        That publication counts always when `every_publication` (realtime: messages go out as
        they happen), else only while a node may wake on a message (lockstep: a longer step
        publishes the same messages). A node still computing is left out: its reply comes
        when it comes (realtime)."""
        candidates = [self.duration_ns]
        for upcoming in (
            self._script[0][0] if self._script else None,
            self.builtins.next_ns(),
            self.edge.tf_due_ns(),
        ):
            if upcoming is not None:
                candidates.append(upcoming)
        wake_ns, listening = self.nodes.next_wake()
        if wake_ns is not None:
            candidates.append(wake_ns)
        if every_publication or listening:
            candidates.append(round(self.sim.next_publication_s() * NS_PER_S))
        return min(candidates)

    def advance_to(self, time_ns: int) -> None:
        """Step the robot to run time `time_ns`, routing what it publishes; then what falls due
        by then: scripted commands, built-ins' ticks, finishing nodes' ends, /tf."""
        if time_ns > self.time_ns:
            try:
                published = self.sim.step((time_ns - self.time_ns) / NS_PER_S)
            except SimulationError as error:
                if self.real_robot:
                    raise RunEnd(RunState.FAILED, f"failed: {error}") from None
                raise RunEnd(RunState.FAILED, f"failed: the simulation stopped: {error}") from None
            self.time_ns = time_ns
            for item in published:
                self.edge.from_robot(item.topic, item.message, item.time_s, time_ns)
            for event in self.sim.drain_events():
                if event.kind is EventKind.LEFT_BOUNDS:
                    log.debug("run %s: robot left the bounds at %.3f s", self.run_id, event.time_s)
        while self._script and self._script[0][0] <= self.time_ns:
            _, command = self._script.pop(0)
            controls.apply(self, command)
        if self.builtins:
            self.builtins.tick(self)
        if any(slot.finishing for slot in self.nodes.order):
            self.nodes.poll_finishing()
        self.outputs.log("robot", self.sim.take_logs())  # a real robot's own loginfo
        self.edge.check_in_map()
        if self.time_ns >= self.edge.next_tf_ns:
            self.edge.record_tf(self.time_ns)
        if self.recorder.error:
            raise RunEnd(RunState.FAILED, f"failed: {self.recorder.error}")

    def wake(self, slot: NodeSlot, now_ns: int) -> None:
        """Lockstep: wake a node and handle its reply before anything else happens."""
        self.nodes.wake(slot, now_ns)

    def begin_wake(self, slot: NodeSlot, now_ns: int) -> None:
        """Realtime: wake a node; its reply is collected when it comes (collect_replies)."""
        self.nodes.begin_wake(slot, now_ns)

    def collect_replies(self) -> bool:
        """Realtime: handle the replies that have come; True if any did."""
        return self.nodes.collect_replies()

    def reply_fds(self) -> list[int]:
        """Realtime: fds that become readable when a computing node answers."""
        return self.nodes.reply_fds()
