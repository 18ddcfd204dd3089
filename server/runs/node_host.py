"""How a run hosts its sandboxed nodes (sandbox/node_process.py), as builtin_host.py hosts the
built-in ones: starts and loads them, wakes them with what waits for them on the bus, acts on
their replies (what they published goes to the run's routing, `route`), says which are due, and
ends them with the run. A node's end (an error, a kill) ends the run through `RunEnd`.
"""

from __future__ import annotations

import time
from collections.abc import Callable

from sandbox.artifact_intake import within_run_room
from sandbox.launcher import Launcher
from sandbox.limits import DEFAULT_LIMITS
from sandbox.node_process import NodeState
from sandbox.protocol import Artifact, Envelope, Exited, Finishing, NodeInfo, Outcome, Yield
from sandbox.units import NS_PER_S
from server.runs.bus import TopicBus
from server.runs.outputs import RunOutputs
from server.runs.recorder import Recorder
from server.runs.result import RunEnd
from server.runs.slots import NodeSlot
from server.runs.spec import NodeSpec
from server.runs.state import RunState

Route = Callable[[NodeSlot, list[Envelope]], None]  # what a node published, to the run


class NodeHost:
    def __init__(
        self, nodes: tuple[NodeSpec, ...], bus: TopicBus, outputs: RunOutputs, route: Route
    ) -> None:
        self.slots = {node.name: NodeSlot(node) for node in nodes}
        self.order = list(self.slots.values())  # launch-file order: who wakes first
        self.bus = bus
        self.outputs = outputs
        self.route = route
        self._artifact_room_bytes = DEFAULT_LIMITS.artifact_total_bytes  # start(): launcher's

    # ----------------------------------------------------------------------------- start, end
    def start(
        self,
        launcher: Launcher,
        info: Callable[[NodeSpec], NodeInfo],
        files: tuple[tuple[str, bytes], ...],
    ) -> None:
        self._artifact_room_bytes = launcher.limits.artifact_total_bytes
        for slot in self.order:
            self.bus.add_node(slot.name)
            slot.process = launcher.start(slot.name)
        replies = []
        artifacts = [Artifact(path, data) for path, data in files]
        for slot in self.order:
            node = slot.spec
            reply = slot.process.load(node.code, node.filename, node.api, info(node), artifacts)
            replies.append((slot, reply))
        # Every node's subscriptions are known before anything published at start-up is
        # routed, so launch-file order does not lose a first message (as a latched topic).
        for slot, reply in replies:
            if isinstance(reply, Yield):
                self.bus.declare(slot.name, reply.advertised, reply.subscribed)
        for slot, reply in replies:
            self.handle_reply(slot, reply, timed=False)

    def end_all(
        self, end_state: RunState, reason: str, recorder: Recorder | None
    ) -> tuple[RunState, str]:
        """End every node (their files and figures into `recorder`); the run's end, changed if
        a node that was finishing failed in what it did after its control part."""
        for slot in self.order:
            finishing = slot.finishing
            self._end(slot, reason, recorder)
            late = slot.exited
            if finishing and late is not None and end_state is RunState.FINISHED:
                if late.outcome is Outcome.ERROR and late.error is not None:
                    slot.log(late.error.traceback.rstrip("\n").split("\n"), self.outputs)
                    where = f" at line {late.error.line}" if late.error.line else ""
                    end_state = RunState.FAILED
                    reason = f"failed: node {slot.name} raised {late.error.type}{where}"
                elif late.outcome in (Outcome.KILLED, Outcome.CRASHED):
                    end_state, reason = RunState.FAILED, f"failed: {late.reason}"
        return end_state, reason

    def _end(self, slot: NodeSlot, reason: str, recorder: Recorder | None) -> None:
        process = slot.process
        if process is None:
            return
        try:
            exited = slot.exited or process.shutdown(reason)
            slot.exited = exited
            self._collect_logs(slot)
            if recorder is not None and exited.artifacts:
                # Each node's files were held to the caps as they arrived (NodeProcess); the
                # total cap holds for the run's nodes together too.
                exited = within_run_room(exited, process.limits, self._artifact_room_bytes)
                self._artifact_room_bytes -= sum(len(a.data) for a in exited.artifacts)
                recorder.write_artifacts(slot.name, [(a.name, a.data) for a in exited.artifacts])
            if exited.notes:  # what the collector skipped, what the server refused: in the log
                slot.log([f"[artifacts] {note}" for note in exited.notes], self.outputs)
        finally:
            process.close()
            slot.process = None

    def metrics(self) -> dict[str, dict]:
        nodes = {}
        for slot in self.order:
            summary = slot.metrics.summary()
            summary["outcome"] = str(slot.exited.outcome) if slot.exited else None
            summary["dropped_messages"] = (
                self.bus.dropped(slot.name) if slot.name in self.bus.nodes else 0
            )
            nodes[slot.name] = summary
        return nodes

    # ----------------------------------------------------------------------------- replies
    def handle_reply(
        self, slot: NodeSlot, reply: Yield | Finishing | Exited, timed: bool = True
    ) -> None:
        """Act on what a node said when it went back to sleep (or ended). `timed`: the reply
        answers a wake, so its wall time is a step's compute time (not start-up)."""
        if timed and not slot.finishing:
            slot.metrics.compute.add(time.perf_counter() - slot.woken_at_wall)
        self._collect_logs(slot)
        if isinstance(reply, Yield):
            self.bus.declare(slot.name, reply.advertised, reply.subscribed)
            if reply.unsubscribed:
                self.bus.unsubscribe(slot.name, reply.unsubscribed)
            self.route(slot, reply.published)
            slot.wake_at_ns = None if reply.wake_at_s is None else round(reply.wake_at_s * NS_PER_S)
            slot.wake_on = None if reply.wake_on is None else frozenset(reply.wake_on)
            return
        self.route(slot, reply.published)
        self.bus.remove_node(slot.name)
        if isinstance(reply, Finishing):
            # The node's part in the run is over (its hooks' last messages are routed above);
            # its figures and files come with its Exited, within the end budget.
            slot.done, slot.finishing = True, True
            slot.log([f"[run] node finishing: {reply.reason}"], self.outputs)
            if all(s.done for s in self.order):
                raise RunEnd(RunState.FINISHED, "finished: every node ended")
            return
        slot.exited, slot.done, slot.finishing = reply, True, False
        if reply.error is not None:  # the student's traceback belongs in the node's log
            slot.log(reply.error.traceback.rstrip("\n").split("\n"), self.outputs)
        if reply.outcome is Outcome.FINISHED:
            if all(s.done for s in self.order):
                raise RunEnd(RunState.FINISHED, "finished: every node ended")
            return
        if reply.outcome is Outcome.ERROR and reply.error is not None:
            where = f" at line {reply.error.line}" if reply.error.line else ""
            raise RunEnd(
                RunState.FAILED, f"failed: node {slot.name} raised {reply.error.type}{where}"
            )
        raise RunEnd(RunState.FAILED, f"failed: {reply.reason}")

    def _collect_logs(self, slot: NodeSlot) -> None:
        if slot.process is None:
            return
        lines = slot.process.logs.take()
        if lines:
            slot.log(lines, self.outputs)

    def poll_finishing(self) -> None:
        """Collect the Exited of nodes that are finishing (or end them past their budget)."""
        for slot in self.order:
            if slot.finishing and slot.process is not None:
                exited = slot.process.poll_finished()
                if exited is not None:
                    self.handle_reply(slot, exited)

    # ----------------------------------------------------------------------------- waking
    def _is_due(self, slot: NodeSlot, now_ns: int) -> bool:
        """Is the sleeping node to be woken at `now_ns`: its time has come, or a message it
        waits for (any, while spinning; or one of its wake_on topics) is there."""
        if slot.wake_at_ns is not None and slot.wake_at_ns <= now_ns:
            return True
        if slot.wake_on is None:
            return slot.wake_at_ns is None and self.bus.has_pending(slot.name)
        return self.bus.has_pending_on(slot.name, slot.wake_on)

    def due(self, now_ns: int) -> list[NodeSlot]:
        """The sleeping nodes to wake at `now_ns`, in launch-file order."""
        return [
            slot
            for slot in self.order
            if not slot.done
            and slot.process is not None
            and slot.process.state is NodeState.SLEEPING
            and self._is_due(slot, now_ns)
        ]

    def next_wake(self) -> tuple[int | None, bool]:
        """(the earliest wake time [ns] of a sleeping node, whether a message can wake one
        before its wake time: spinning, or waiting on topics). Nodes still computing are left
        out: their reply comes when it comes."""
        earliest, listening = None, False
        for slot in self.order:
            if slot.done or slot.computing:
                continue
            if slot.wake_at_ns is None or slot.wake_on is not None:
                listening = True
            if slot.wake_at_ns is not None and (earliest is None or slot.wake_at_ns < earliest):
                earliest = slot.wake_at_ns
        return earliest, listening

    def wake(self, slot: NodeSlot, now_ns: int) -> None:
        """Wake one node now and handle its reply (a node ended meanwhile by an earlier one's
        reply is left alone)."""
        if slot.done:
            return
        self.begin_wake(slot, now_ns)
        self.handle_reply(slot, slot.process.poll_reply(None))

    def begin_wake(self, slot: NodeSlot, now_ns: int) -> None:
        """Wake one node with what waits for it, without waiting for its reply."""
        deliveries, newest_sensor_s = self.bus.take(slot.name)
        if newest_sensor_s is not None:
            slot.newest_sensor_s = newest_sensor_s
        if slot.last_wake_ns is not None:
            slot.metrics.period.add((now_ns - slot.last_wake_ns) / NS_PER_S)
        if slot.wake_at_ns is not None and slot.wake_at_ns <= now_ns:  # not a message first
            slot.metrics.woke_late(now_ns / NS_PER_S, (now_ns - slot.wake_at_ns) / NS_PER_S)
        slot.last_wake_ns = now_ns
        slot.metrics.wakes += 1
        slot.woken_at_wall = time.perf_counter()
        graph = None
        if slot.graph_version != self.bus.version:
            graph, slot.graph_version = self.bus.graph_topics(), self.bus.version
        slot.process.begin_wake(now_ns / NS_PER_S, deliveries, graph)

    def collect_replies(self) -> bool:
        """Handle the replies of computing nodes that have answered; True if any did."""
        replied = False
        for slot in self.order:
            if not slot.done and slot.computing:
                reply = slot.process.poll_reply(0.0)
                if reply is not None:
                    self.handle_reply(slot, reply)
                    replied = True
        return replied

    def reply_fds(self) -> list[int]:
        """fds that become readable when a computing node answers."""
        return [
            fd
            for slot in self.order
            if not slot.done and slot.computing
            for fd in slot.process.reply_fds
        ]
