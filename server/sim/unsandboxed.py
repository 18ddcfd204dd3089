"""UNSANDBOXED: run a step-API controller in this very process against a `Simulation`, for
notebooks and unit tests. The controller runs with every right this process has (files, network,
the server's memory): use it on code you trust, never on a student's submission. Students' code
runs in the sandbox (server/runs, sandbox/); every call here logs a warning that says so.

    from server.sim.unsandboxed import run_step_controller

    def step(obs):
        if obs.Distance is None:
            return None
        return (0.1, 0.0) if obs.Distance.data > 20 else (0.0, 0.0)

    result = run_step_controller(step, "crowbot", "wall_approach", duration_s=5.0, seed=0)
    result.poses[-1]      # (time [s], x [m], y [m], yaw [rad]) at the end
    result.messages       # what the robot published and the controller sent, in time order

The controller gets what a lockstep sandboxed run gives it: the node side is the sandbox's own
(`sandbox.runtime.NodeRuntime` and `sandbox.step_api.StepController` build `obs` and turn what
step() returns into messages, serialized as on the wire), and `_LockstepParent` below plays the
run engine's lockstep clock (server/runs/clocks.py) for one node: it wakes the node at the time
it asked for with the messages of its topics published since its last wake (nothing from before
it subscribed), applies its commands at that time, and advances the simulation to the next wake,
by at least one physics tick. Same controller, same seed: the same pose trace as the sandboxed
run. What differs: `time.time()` and `time.sleep()` stay the process's own (the sandbox makes
them follow the run's clock), print() writes to this process's stdout, and there are no built-in
nodes, faults, goal or /tf. ROS 1 messages only, as the step API uses.
"""

from __future__ import annotations

import ast
import inspect
import logging
import types
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from sandbox import python_ast
from sandbox.msgs import get_message_class
from sandbox.protocol import Clock, Envelope, NodeInfo, RobotTopic, Shutdown, Wake, Yield
from sandbox.ros_errors import ROSInterruptException
from sandbox.runtime import NodeRuntime
from sandbox.step_api import StepController
from sandbox.units import NS_PER_S
from sandbox.vclock import NodeClock
from server.sim.robots.base import CommandError, Direction
from server.sim.simulation import Simulation, SimulationError
from server.sim.state import Pose2D
from server.sim.world import World

log = logging.getLogger("robodojo.sim.unsandboxed")

NODE_NAME = "controller"  # the node's name, as a run names a step-API node by its spec
GOAL_TOPIC = "goal"  # a run offers this topic to every node (server/runs/robot_edge.py)
GOAL_TYPE = "geometry_msgs/PoseStamped"


@dataclass(frozen=True, slots=True)
class Recorded:
    """One message of the run: published by `source` ("robot" or the node) at `time_s` [s]."""

    time_s: float
    topic: str
    source: str
    message: object


@dataclass(slots=True)
class StepRunResult:
    """What an unsandboxed run leaves: `poses` (N, 4) rows (time [s], x [m], y [m], yaw [rad]),
    the true pose at time 0, at each wake of the controller and at the end; `messages` in time
    order; `logs`, the commands the robot refused, one line each (as a run's node log has
    them); `sim`, the simulation as the run left it (stopped, as every run ends)."""

    poses: np.ndarray
    messages: list[Recorded]
    logs: list[str]
    sim: Simulation

    def topic(self, name: str) -> list[Recorded]:
        """The messages on topic `name`, in time order."""
        return [m for m in self.messages if m.topic == name]


@dataclass
class _LockstepParent:
    """The run's end of the node's link, in-process: each `send(Yield)` is answered by the
    `receive()` that follows with a `Wake` (or a `Shutdown` at the end of the run)."""

    sim: Simulation
    duration_ns: int
    time_ns: int = 0
    subscribed: set[str] = field(default_factory=set)
    pending: dict[str, Envelope] = field(default_factory=dict)  # the newest per topic
    messages: list[Recorded] = field(default_factory=list)
    poses: list[tuple[float, float, float, float]] = field(default_factory=list)
    logs: list[str] = field(default_factory=list)
    _reply: Wake | Shutdown | None = None

    def send(self, frame: object) -> None:
        if not isinstance(frame, Yield):
            raise TypeError(f"the node sent {type(frame).__name__}; only Yield is expected")
        self.subscribed.update(decl.name for decl in frame.subscribed)
        self.subscribed.difference_update(frame.unsubscribed)
        for envelope in frame.published:
            self._from_node(envelope)
        if frame.wake_at_s is None:
            raise SimulationError("a step-API node always sleeps until its next period")
        wake_ns = round(frame.wake_at_s * NS_PER_S)
        if wake_ns > self.time_ns:
            # As the lockstep clock: on to the wake (or the end), by at least one tick.
            tick_ns = round(self.sim.tick_s * NS_PER_S)
            self._advance_to(max(min(wake_ns, self.duration_ns), self.time_ns + tick_ns))
        if self.time_ns >= self.duration_ns:  # the run covers [0, duration)
            self._reply = Shutdown("the run reached its duration")
            return
        deliveries = list(self.pending.values())
        self.pending.clear()
        self._reply = Wake(self.time_ns / NS_PER_S, deliveries)

    def receive(self) -> object:
        reply, self._reply = self._reply, None
        if reply is None:
            raise RuntimeError("receive() before send(): the node must yield first")
        return reply

    def _advance_to(self, time_ns: int) -> None:
        for published in self.sim.step((time_ns - self.time_ns) / NS_PER_S):
            message = published.message
            self.messages.append(Recorded(published.time_s, published.topic, "robot", message))
            if published.topic in self.subscribed:
                envelope = Envelope(published.topic, message._type, message.serialize())
                self.pending.pop(published.topic, None)  # keep arrival order: newest last
                self.pending[published.topic] = envelope
        self.time_ns = time_ns
        self.note_pose()

    def note_pose(self) -> None:
        pose = self.sim.state.pose
        self.poses.append((self.time_ns / NS_PER_S, pose.x, pose.y, pose.yaw))

    def _from_node(self, envelope: Envelope) -> None:
        """Route what the node published: a command into the robot (refused with a log line,
        as a run refuses it), anything else only recorded."""
        now_s = self.time_ns / NS_PER_S
        try:
            message = get_message_class(envelope.type).deserialize(envelope.data)
        except (KeyError, ValueError) as error:
            self.logs.append(f"[robot] rejected {envelope.topic}: {error}")
            return
        self.messages.append(Recorded(now_s, envelope.topic, NODE_NAME, message))
        if envelope.topic not in self.sim.robot.commands:
            return
        try:
            self.sim.apply(envelope.topic, message)
        except (SimulationError, CommandError, ValueError) as error:
            self.logs.append(f"[robot] rejected {envelope.topic}: {error}")


def _node_info(sim: Simulation) -> NodeInfo:
    """What a ROS 1 run tells a node about the robot's topics (and the run's goal topic)."""
    topics = [RobotTopic(t.name, t.type_name, str(t.direction), t.rate_hz) for t in sim.topics]
    topics.append(RobotTopic(GOAL_TOPIC, GOAL_TYPE, str(Direction.PUBLISH)))
    velocity = next(iter(sim.robot.velocity_topics()), None)
    return NodeInfo(
        node_name=NODE_NAME,
        robot=sim.robot.id,
        robot_topics=topics,
        velocity_topic=velocity,
        clock=Clock.LOCKSTEP,
    )


def _namespace(
    controller: str | types.ModuleType | Callable[[Any], Any],
    rate_hz: float | None,
    subscribe: Sequence[str] | None,
    setup: Callable[..., Any] | None,
) -> tuple[dict[str, Any], ast.Module]:
    """The module namespace StepController reads (step, RATE_HZ, SUBSCRIBE, setup) and its
    syntax tree (for the line numbers of its sentences)."""
    if isinstance(controller, str):  # a step-API file's source, as a run loads it
        from sandbox.host import install_ros_compat  # `from std_msgs.msg import ...`

        install_ros_compat(1)
        tree = python_ast.parse(controller, "<controller>")
        module = types.ModuleType("step_controller")
        exec(compile(tree, "<controller>", "exec"), module.__dict__)
        namespace = module.__dict__
    elif isinstance(controller, types.ModuleType):
        namespace = dict(vars(controller))
        source = inspect.getsource(controller)
        tree = python_ast.parse(source)
    elif callable(controller):
        namespace = {"step": controller}
        tree = ast.Module(body=[], type_ignores=[])
    else:
        raise TypeError(
            "controller must be a step function, a module with `step`, or its source code, "
            f"got {type(controller).__name__}"
        )
    given = {"RATE_HZ": rate_hz, "SUBSCRIBE": subscribe, "setup": setup}
    namespace.update({key: value for key, value in given.items() if value is not None})
    if not callable(namespace.get("step")):
        raise TypeError("the step API needs a function `step(obs)`; the controller has none")
    return namespace, tree


def run_step_controller(
    controller: str | types.ModuleType | Callable[[Any], Any],
    robot: str,
    world: str | World,
    duration_s: float,
    seed: int = 0,
    *,
    spawn: str | Pose2D | None = None,
    rate_hz: float | None = None,
    subscribe: Sequence[str] | None = None,
    setup: Callable[..., Any] | None = None,
) -> StepRunResult:
    """UNSANDBOXED (module docstring): run `controller` against `Simulation(robot, world,
    seed=seed, spawn=spawn)` for `duration_s` [s] of simulated time, in lockstep.

    `controller` is a step function, a module that has one, or a step-API file's source;
    `rate_hz`, `subscribe` and `setup` stand for the file's RATE_HZ, SUBSCRIBE and setup().
    What the controller raises is raised here, with its own traceback."""
    if not (isinstance(duration_s, (int, float)) and duration_s > 0):
        raise SimulationError(f"duration_s must be a positive number of seconds, got {duration_s}")
    log.warning(
        "UNSANDBOXED: running a step controller in this process on %s in %s; only for code "
        "you trust",
        robot,
        world if isinstance(world, str) else world.id,
    )
    sim = Simulation(robot, world, seed=seed, spawn=spawn)
    namespace, tree = _namespace(controller, rate_hz, subscribe, setup)
    parent = _LockstepParent(sim, round(duration_s * NS_PER_S))
    for published in sim.reset():  # time 0: before the node subscribed, as in a run
        parent.messages.append(Recorded(0.0, published.topic, "robot", published.message))
    parent.note_pose()
    info = _node_info(sim)
    node = NodeRuntime(parent, info, NodeClock(Clock.LOCKSTEP, info.start_time_s), "<controller>")
    node.node_name, node.implicit_name = "/" + NODE_NAME, True
    try:
        StepController(node, namespace, tree).run()
    except ROSInterruptException:  # the run reached its duration: the node's normal end
        pass
    finally:
        sim.stop()  # every run ends with zero velocity
    parent.messages.sort(key=lambda m: m.time_s)  # stable: arrival order within an instant
    return StepRunResult(np.array(parent.poses), parent.messages, parent.logs, sim)
