"""The step API: a controller is a function called once per control period.

    RATE_HZ = 20                    # optional; default: the robot's default rate
    SUBSCRIBE = ["Distance"]        # optional; default: every sensor topic of the robot

    def setup(info):                # optional; info is the NodeInfo (robot, topics, params)
        ...

    def step(obs):
        if obs.Distance is None:    # nothing arrived yet
            return None             # publish nothing
        return 0.1, 0.0             # (v [m/s], w [rad/s]) on the robot's velocity topic

`obs` holds the latest message of each subscribed topic (None until one arrives), by attribute
or by key (`obs["ultrasonic/range_0"]`), and `obs.time`, the node's time in seconds. step()
returns None, a Twist (sent on the velocity topic), a (v, w) pair of numbers, or a mapping
topic -> message. In the mapping, a plain value fills the message's data field ({"Leds":
[255, 0, 0]}) and a (v, w) pair builds a Twist ({"cmd_vel": (0.1, 0.0)}). Call k (from 0)
happens at start + k / RATE_HZ.
Examples, one per robot: examples/step_api/.
"""

from __future__ import annotations

import ast
import difflib
import inspect
from collections.abc import Mapping
from numbers import Real
from typing import Any

from sandbox.msgs import Message
from sandbox.msgs.geometry_msgs import Twist
from sandbox.runtime import NodeRuntime, ROSException
from sandbox.student_errors import StepError
from sandbox.vclock import seconds_to_ns

MAX_RATE_HZ = 1000.0  # [Hz] faster than any robot publishes; beyond it a node only burns CPU
ACCEPTED = "None, a Twist, a (v, w) pair of numbers, or a dict mapping topic names to messages"


class Observation:
    """The latest message of each subscribed topic, and `time` [s]."""

    __slots__ = ("_robot_sensors", "_values", "time")

    def __init__(self, time_s: float, values: dict[str, Any], robot_sensors: list[str]) -> None:
        self.time = time_s
        self._values = values
        self._robot_sensors = robot_sensors

    def _missing(self, name: str) -> str:
        valid = list(self._values)
        if name in self._robot_sensors:
            return (
                f"obs has no '{name}': it is not in SUBSCRIBE; add it there, e.g. "
                f"SUBSCRIBE = {[*valid, name]!r}"
            )
        close = difflib.get_close_matches(name, [*valid, "time"], n=1)
        hint = f"did you mean '{close[0]}'? " if close else ""
        return f"obs has no '{name}'; {hint}valid names: {', '.join(valid)} and time"

    def __getitem__(self, name: str) -> Any:
        key = name.lstrip("/") if isinstance(name, str) else name
        if key == "time":
            return self.time
        if key not in self._values:
            raise KeyError(self._missing(str(name)))
        return self._values[key]

    def __getattr__(self, name: str) -> Any:
        if name.startswith("__"):
            raise AttributeError(name)
        if name not in self._values:
            raise AttributeError(self._missing(name))
        return self._values[name]

    def get(self, name: str, default: Any = None) -> Any:
        value = self._values.get(name.lstrip("/"))
        return default if value is None else value

    def __contains__(self, name: object) -> bool:
        return name in self._values or name == "time"

    def keys(self) -> list[str]:
        return list(self._values)

    def __iter__(self) -> Any:
        return iter(self._values)

    def __repr__(self) -> str:
        shown = ", ".join(
            f"{k}={type(v).__name__ if v is not None else None}" for k, v in self._values.items()
        )
        return f"Observation(time={self.time:.3f}, {shown})"


def _assignment_line(tree: ast.Module, name: str) -> int | None:
    for node in tree.body:
        targets = node.targets if isinstance(node, ast.Assign) else [getattr(node, "target", None)]
        if any(isinstance(t, ast.Name) and t.id == name for t in targets):
            return node.lineno
    return None


def _rate_hz(namespace: dict[str, Any], default: float, tree: ast.Module) -> float:
    rate = namespace.get("RATE_HZ", default)
    if not isinstance(rate, Real) or isinstance(rate, bool) or not 0 < rate <= MAX_RATE_HZ:
        raise StepError(
            f"RATE_HZ must be a number of calls per second, 0 < RATE_HZ <= {MAX_RATE_HZ:g}; "
            f"got {rate!r}",
            _assignment_line(tree, "RATE_HZ"),
        )
    return float(rate)


def _subscriptions(namespace: dict[str, Any], node: NodeRuntime, tree: ast.Module) -> list[str]:
    sensors = node.sensor_topics()
    wanted = namespace.get("SUBSCRIBE")
    if wanted is None:
        return sensors
    line = _assignment_line(tree, "SUBSCRIBE")
    if isinstance(wanted, str) or not isinstance(wanted, list | tuple):
        raise StepError(f"SUBSCRIBE must be a list of topic names, got {wanted!r}", line)
    names = []
    for item in wanted:
        name = item.lstrip("/") if isinstance(item, str) else item
        if name not in sensors:
            close = difflib.get_close_matches(str(name), sensors, n=1)
            hint = f"did you mean '{close[0]}'? " if close else ""
            raise StepError(
                f"SUBSCRIBE names {item!r}, which is not a sensor topic of robot "
                f"{node.info.robot}; {hint}sensor topics: {', '.join(sensors)}",
                line,
            )
        names.append(name)
    return names


_PLAIN_NUMBERS = (float, int)


def _is_number(x: Any) -> bool:
    # Exact float/int first: the ABC check (numpy scalars) costs ~1 us, paid every period.
    if type(x) in _PLAIN_NUMBERS:
        return True
    return isinstance(x, Real) and not isinstance(x, bool)


def _is_pair(value: Any) -> bool:
    """A (v, w) pair of plain numbers (numpy scalars count, booleans do not)."""
    return (
        isinstance(value, tuple | list)
        and len(value) == 2
        and _is_number(value[0])
        and _is_number(value[1])
    )


def _twist(v: Any, w: Any) -> Twist:
    command = Twist()
    command.linear.x = float(v)
    command.angular.z = float(w)
    return command


def _describe(value: Any) -> str:
    text = repr(value)
    text = text if len(text) <= 60 else text[:57] + "..."
    return f"a {type(value).__name__} ({text})"


class StepController:
    """Runs a step-API module: setup(info) once, then step(obs) at each period."""

    def __init__(self, node: NodeRuntime, namespace: dict[str, Any], tree: ast.Module) -> None:
        self.node = node
        self.step = namespace["step"]
        step_line = getattr(getattr(self.step, "__code__", None), "co_firstlineno", None)
        self.step_line = step_line
        if not callable(self.step):
            raise StepError(f"step must be a function, got {_describe(self.step)}", None)
        self.rate_hz = _rate_hz(namespace, node.info.default_rate_hz, tree)
        self.topics = _subscriptions(namespace, node, tree)
        self.setup = namespace.get("setup")
        self._decoded: dict[str, tuple[Any, Any]] = {}  # topic -> (envelope, message)
        self._sensor_topics = node.sensor_topics()

    def run(self) -> None:
        node = self.node
        if callable(self.setup):
            takes_info = bool(inspect.signature(self.setup).parameters)
            self.setup(node.info) if takes_info else self.setup()
        for topic in self.topics:
            node.subscribe(topic, node.topic_class(topic), None)
        start_ns = seconds_to_ns(node.info.start_time_s)
        calls = 0
        while not node.is_shutdown:
            node.sleep_until(start_ns + round(calls * 1e9 / self.rate_hz))
            result = self.step(self.observation())
            self.apply(result)
            calls += 1

    def observation(self) -> Observation:
        values: dict[str, Any] = {}
        for topic in self.topics:
            envelope = self.node.latest.get(topic)
            cached = self._decoded.get(topic)
            if envelope is None:
                values[topic] = None
            elif cached is not None and cached[0] is envelope:
                values[topic] = cached[1]
            else:
                message = self.node.topic_class(topic).deserialize(envelope.data)
                self._decoded[topic] = (envelope, message)
                values[topic] = message
        return Observation(self.node.clock.now_s(), values, self._sensor_topics)

    def apply(self, result: Any) -> None:
        """Publish what step() returned."""
        if result is None:
            return
        try:
            if isinstance(result, Twist):
                self._publish(self._velocity_topic(), result)
            elif isinstance(result, Mapping):
                for topic, value in result.items():
                    if value is not None:
                        self._publish(topic, value)
            elif _is_pair(result):
                self._publish(self._velocity_topic(), _twist(*result))
            elif isinstance(result, Message):
                raise StepError(
                    f"step() returned a {result._type} message; return it in a dict that says "
                    f"which topic it goes to, e.g. {{'topic': msg}}",
                    self.step_line,
                )
            else:
                raise StepError(
                    f"step() returned {_describe(result)}; return {ACCEPTED}", self.step_line
                )
        except ROSException as error:
            raise StepError(
                f"step() returned a command that cannot be sent: {error}", self.step_line
            ) from None

    def _velocity_topic(self) -> str:
        topic = self.node.info.velocity_topic
        if topic is None:
            raise StepError(
                f"robot {self.node.info.robot} has no velocity topic; return a dict mapping "
                f"command topics ({', '.join(self.node.command_topics())}) to messages",
                self.step_line,
            )
        return topic

    def _publish(self, topic: Any, value: Any) -> None:
        node = self.node
        if isinstance(value, Message):
            name = node.advertise(topic, type(value))
        else:
            name = node.advertise(topic, node.topic_class(_clean(topic, node)))
            data_class = node.topic_class(name)
            try:
                if data_class is Twist and _is_pair(value):
                    value = _twist(*value)
                elif "data" in data_class.__slots__:  # {"Leds": [255, 0, 0]}: the data field
                    value = data_class(data=value)
                else:
                    value = data_class(value)
            except (TypeError, ValueError) as error:
                raise ROSException(
                    f"'{name}' carries {data_class._type}; cannot build one from "
                    f"{_describe(value)}: {error}"
                ) from None
        node.publish(name, value)


def _clean(topic: Any, node: NodeRuntime) -> str:
    """The topic name for a plain value, which needs a known topic to know its type."""
    name = topic.lstrip("/") if isinstance(topic, str) else topic
    try:
        node.topic_class(name)
    except KeyError:
        raise node.unknown_topic(str(name)) from None
    return name
