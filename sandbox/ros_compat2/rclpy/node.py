"""rclpy.node.Node: names, publishers, subscriptions, timers, services, parameters, the graph.

As rclpy/node.py, where a student can observe it: the constructor's keyword arguments and
defaults, name and namespace validation (InvalidNodeNameException, InvalidNamespaceException),
topic names expanded and remapped as rcl does (sandbox.ros2_names; InvalidTopicNameException),
`qos_profile` as a QoSProfile or a depth (TypeError, ValueError as rclpy), destroy_* returning
whether the entity was the node's. Parameters are the node's own (rclpy/_parameters.py).

Where the node's names come from, strongest first: its `cli_args`, the process's command line
(`rclpy.init(args=...)` or sys.argv, which holds what the run gave the node), then the run's
launch settings (NodeInfo.remaps, namespace and params), as a launch file's `--ros-args`.
Several Nodes in one file share the process's NodeRuntime; each resolves its own names.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import TYPE_CHECKING, Any

from sandbox import ros2_args
from sandbox.ros2_names import (
    RemapRule,
    Ros2NameError,
    bus_name,
    expand_topic_name,
    node_name_and_namespace,
    normalize_namespace,
    remap_topic_name,
    validate_node_name,
)
from sandbox.ros_errors import ROSException
from sandbox.services import is_internal

from . import _state
from ._parameters import ParameterStore
from .callback_groups import CallbackGroup, MutuallyExclusiveCallbackGroup, ReentrantCallbackGroup
from .clock import Clock, ROSClock
from .constants import S_TO_NS
from .context import Context, parse_arguments
from .exceptions import (
    InvalidNamespaceException,
    InvalidNodeNameException,
    InvalidServiceNameException,
    InvalidTopicNameException,
    NotInitializedException,
)
from .logging import get_logger
from .publisher import Publisher
from .qos import QoSProfile, qos_profile_services_default
from .subscription import Subscription
from .timer import Rate, Timer
from .utilities import get_default_context

if TYPE_CHECKING:
    from .client import Client
    from .executors import Executor
    from .impl.rcutils_logger import RcutilsLogger
    from .parameter import Parameter
    from .service import Service


def _name_exception(error: Ros2NameError) -> Exception:
    kinds = {
        "node name": InvalidNodeNameException,
        "namespace": InvalidNamespaceException,
        "service name": InvalidServiceNameException,
    }
    cls = kinds.get(error.kind, InvalidTopicNameException)
    return cls(error.name, error.reason, error.index)


class Node:
    """A ROS 2 node of this process."""

    PARAM_REL_TOL = 1e-6

    def __init__(
        self,
        node_name: str,
        *,
        context: Context | None = None,
        cli_args: list[str] | None = None,
        namespace: str | None = None,
        use_global_arguments: bool = True,
        enable_rosout: bool = True,
        start_parameter_services: bool = True,
        parameter_overrides: list[Parameter] | None = None,
        allow_undeclared_parameters: bool = False,
        automatically_declare_parameters_from_overrides: bool = False,
        enable_logger_service: bool = False,
    ) -> None:
        self._context = get_default_context() if context is None else context
        if self._context.handle is None or not self._context.ok():
            raise NotInitializedException("cannot create node")
        current = _state.state()
        self._publishers: list[Publisher] = []
        self._subscriptions: list[Subscription] = []
        self._clients: list[Client] = []
        self._services: list[Service] = []
        self._timers: list[Timer] = []
        self._guards: list[Any] = []
        self._waitables: list[Any] = []
        self._default_callback_group = MutuallyExclusiveCallbackGroup()
        self._rate_group = ReentrantCallbackGroup()
        self._executor: Executor | None = None
        self.__destroyed = False

        local_args = parse_arguments(list(cli_args)) if cli_args else ros2_args.RosArguments()
        info = current.runtime.info
        launch_rules = [RemapRule(source, target) for source, target in info.remaps.items()]
        if info.namespace not in ("", "/"):
            launch_rules.append(RemapRule("__ns", info.namespace))
        global_args = self._context.arguments if use_global_arguments else ros2_args.RosArguments()
        self.__remaps = [*local_args.remaps, *global_args.remaps, *launch_rules]
        try:
            validate_node_name(node_name)
            namespace = normalize_namespace(namespace)
            self.__name, self.__namespace = node_name_and_namespace(
                self.__remaps, node_name, namespace
            )
        except Ros2NameError as error:
            raise _name_exception(error) from None

        self._clock = ROSClock()
        log_levels = {**global_args.log_levels, **local_args.log_levels}
        self._logger = get_logger(self._logger_name())
        for logger, level in log_levels.items():
            from .logging import get_logging_severity_from_string, set_logger_level

            set_logger_level(logger or "", get_logging_severity_from_string(level))

        overrides = {
            **_flat_launch_params(info.params),
            **global_args.parameters_for(self.__name, self.__namespace),
            **local_args.parameters_for(self.__name, self.__namespace),
        }
        self._parameters = ParameterStore(self, overrides, allow_undeclared_parameters)
        if parameter_overrides is not None:
            self._parameters.add_overrides(parameter_overrides)
        if automatically_declare_parameters_from_overrides:
            self._parameters.declare_overrides()
        if not self._parameters.has("use_sim_time"):
            self._parameters.declare_builtin("use_sim_time", False)

        self._context.track_node(self)
        current.nodes.append(self)
        if current.runtime.node_name is None:
            current.runtime.node_name = self.get_fully_qualified_name()

    # ------------------------------------------------------------------ identity
    def _logger_name(self) -> str:
        parts = [part for part in self.__namespace.split("/") if part]
        return ".".join([*parts, self.__name])

    def get_name(self) -> str:
        return self.__name

    def get_namespace(self) -> str:
        return self.__namespace

    def get_fully_qualified_name(self) -> str:
        return self.__namespace.rstrip("/") + "/" + self.__name

    def get_clock(self) -> Clock:
        return self._clock

    def get_logger(self) -> RcutilsLogger:
        return self._logger

    @property
    def context(self) -> Context:
        return self._context

    @property
    def handle(self) -> Node:
        return self

    @property
    def default_callback_group(self) -> CallbackGroup:
        return self._default_callback_group

    @property
    def executor(self) -> Executor | None:
        return self._executor

    @executor.setter
    def executor(self, new_executor: Executor | None) -> None:
        if self._executor is not None and self._executor is not new_executor:
            self._executor.remove_node(self)
        self._executor = new_executor

    @property
    def publishers(self) -> Iterator[Publisher]:
        yield from self._publishers

    @property
    def subscriptions(self) -> Iterator[Subscription]:
        yield from self._subscriptions

    @property
    def clients(self) -> Iterator[Client]:
        yield from self._clients

    @property
    def services(self) -> Iterator[Service]:
        yield from self._services

    @property
    def timers(self) -> Iterator[Timer]:
        yield from self._timers

    @property
    def guards(self) -> Iterator[Any]:
        yield from self._guards

    @property
    def waitables(self) -> Iterator[Any]:
        yield from self._waitables

    def _entities(self) -> list[Any]:
        """Everything an executor serves for this node, in rclpy's order."""
        return [
            *self._waitables,
            *self._timers,
            *self._subscriptions,
            *self._clients,
            *self._services,
        ]

    def _wake_executor(self) -> None:
        _state.state().refresh_wake_topics()

    # ------------------------------------------------------------------ names
    def resolve_topic_name(self, topic: str, *, only_expand: bool = False) -> str:
        return self._resolve(topic, "topic name", only_expand)

    def resolve_service_name(self, service: str, *, only_expand: bool = False) -> str:
        return self._resolve(service, "service name", only_expand)

    def _resolve(self, name: Any, kind: str, only_expand: bool = False) -> str:
        if not isinstance(name, str):
            raise TypeError(f"a {kind} is a string such as 'cmd_vel', got {name!r}")
        try:
            expanded = expand_topic_name(name, self.__name, self.__namespace, kind)
            if only_expand:
                return expanded
            return remap_topic_name(self.__remaps, expanded, self.__name, self.__namespace)
        except Ros2NameError as error:
            raise _name_exception(error) from None

    def _bus(self, name: Any, kind: str = "topic name") -> str:
        return bus_name(self._resolve(name, kind))

    # ------------------------------------------------------------------ entities
    def _check_alive(self, what: str) -> None:
        if self.__destroyed:
            raise RuntimeError(f"{what} on node '{self.__name}' after destroy_node()")

    @staticmethod
    def _validate_qos_or_depth_parameter(qos_or_depth: Any) -> QoSProfile:
        if isinstance(qos_or_depth, QoSProfile):
            return qos_or_depth
        if isinstance(qos_or_depth, int) and not isinstance(qos_or_depth, bool):
            if qos_or_depth < 0:
                raise ValueError("history depth must be greater than or equal to zero")
            return QoSProfile(depth=qos_or_depth)
        raise TypeError(f"Expected QoSProfile or int, but received {type(qos_or_depth)!r}")

    @staticmethod
    def _check_msg_type(msg_type: Any, what: str) -> None:
        if isinstance(msg_type, type) and isinstance(getattr(msg_type, "_type", None), str):
            return
        shown = type(msg_type).__name__ if not isinstance(msg_type, type) else msg_type.__name__
        raise TypeError(
            f"{what} needs a message class such as std_msgs.msg.String, got {shown!r}"
            + (
                " (an instance: pass the class itself, without ())"
                if not isinstance(msg_type, type)
                else ""
            )
        )

    def create_publisher(
        self,
        msg_type: type,
        topic: str,
        qos_profile: QoSProfile | int,
        *,
        callback_group: CallbackGroup | None = None,
        event_callbacks: Any = None,
        qos_overriding_options: Any = None,
        publisher_class: type[Publisher] = Publisher,
    ) -> Publisher:
        self._check_alive("create_publisher()")
        qos = self._validate_qos_or_depth_parameter(qos_profile)
        self._check_msg_type(msg_type, "create_publisher()")
        bus_topic = self._bus(topic)
        try:
            publisher = publisher_class(self, msg_type, topic, bus_topic, qos, event_callbacks)
        except ROSException as error:
            raise RuntimeError(str(error)) from None
        self._publishers.append(publisher)
        _state.state().check_local_qos(publisher=publisher)
        return publisher

    def create_subscription(
        self,
        msg_type: type,
        topic: str,
        callback: Callable[..., Any],
        qos_profile: QoSProfile | int,
        *,
        callback_group: CallbackGroup | None = None,
        event_callbacks: Any = None,
        qos_overriding_options: Any = None,
        raw: bool = False,
    ) -> Subscription:
        self._check_alive("create_subscription()")
        qos = self._validate_qos_or_depth_parameter(qos_profile)
        self._check_msg_type(msg_type, "create_subscription()")
        if not callable(callback):
            raise TypeError(f"create_subscription() needs a callback function, got {callback!r}")
        group = callback_group or self._default_callback_group
        bus_topic = self._bus(topic)
        try:
            subscription = Subscription(
                self, msg_type, topic, bus_topic, callback, group, qos, raw, event_callbacks
            )
        except ROSException as error:
            raise RuntimeError(str(error)) from None
        group.add_entity(subscription)
        self._subscriptions.append(subscription)
        _state.state().check_local_qos(subscription=subscription)
        self._wake_executor()
        return subscription

    def create_timer(
        self,
        timer_period_sec: float,
        callback: Callable[..., Any] | None,
        callback_group: CallbackGroup | None = None,
        clock: Clock | None = None,
        autostart: bool = True,
    ) -> Timer:
        self._check_alive("create_timer()")
        period_ns = int(float(timer_period_sec) * S_TO_NS)
        group = callback_group or self._default_callback_group
        timer = Timer(
            callback,
            group,
            period_ns,
            clock or self._clock,
            context=self._context,
            autostart=autostart,
        )
        group.add_entity(timer)
        self._timers.append(timer)
        self._wake_executor()
        return timer

    def create_rate(self, frequency: float, clock: Clock | None = None) -> Rate:
        if frequency <= 0:
            raise ValueError("frequency must be > 0")
        timer = self.create_timer(1.0 / frequency, None, self._rate_group, clock)
        self._timers.remove(timer)  # a rate's timer is the rate's own, not the executor's
        return Rate(timer, context=self._context)

    def create_guard_condition(
        self, callback: Callable[[], Any], callback_group: CallbackGroup | None = None
    ) -> Any:
        from .guard_condition import GuardCondition

        group = callback_group or self._default_callback_group
        guard = GuardCondition(callback, group)
        group.add_entity(guard)
        self._guards.append(guard)
        return guard

    def create_client(
        self,
        srv_type: Any,
        srv_name: str,
        *,
        qos_profile: QoSProfile = qos_profile_services_default,
        callback_group: CallbackGroup | None = None,
    ) -> Client:
        from .client import Client

        self._check_alive("create_client()")
        group = callback_group or self._default_callback_group
        client = Client(self, srv_type, srv_name, self._bus(srv_name, "service name"), group)
        group.add_entity(client)
        self._clients.append(client)
        self._wake_executor()
        return client

    def create_service(
        self,
        srv_type: Any,
        srv_name: str,
        callback: Callable[[Any, Any], Any],
        *,
        qos_profile: QoSProfile = qos_profile_services_default,
        callback_group: CallbackGroup | None = None,
    ) -> Service:
        from .service import Service

        self._check_alive("create_service()")
        group = callback_group or self._default_callback_group
        service = Service(
            self, srv_type, srv_name, self._bus(srv_name, "service name"), callback, group
        )
        group.add_entity(service)
        self._services.append(service)
        self._wake_executor()
        return service

    def add_waitable(self, waitable: Any) -> None:
        self._waitables.append(waitable)
        self._wake_executor()

    def remove_waitable(self, waitable: Any) -> None:
        self._waitables.remove(waitable)
        self._wake_executor()

    # ------------------------------------------------------------------ destruction
    def _destroy_from(self, entities: list[Any], entity: Any) -> bool:
        if entity in entities:
            entities.remove(entity)
            entity.destroy()
            self._wake_executor()
            return True
        return False

    def destroy_publisher(self, publisher: Publisher) -> bool:
        return self._destroy_from(self._publishers, publisher)

    def destroy_subscription(self, subscription: Subscription) -> bool:
        return self._destroy_from(self._subscriptions, subscription)

    def destroy_client(self, client: Client) -> bool:
        return self._destroy_from(self._clients, client)

    def destroy_service(self, service: Service) -> bool:
        return self._destroy_from(self._services, service)

    def destroy_timer(self, timer: Timer) -> bool:
        return self._destroy_from(self._timers, timer)

    def destroy_guard_condition(self, guard: Any) -> bool:
        return self._destroy_from(self._guards, guard)

    def destroy_rate(self, rate: Rate) -> bool:
        rate.destroy()
        return True

    def destroy_node(self) -> None:
        """Free the node's publishers, subscriptions, clients, services and timers."""
        if self.__destroyed:
            return
        self._context.untrack_node(self)
        for entities in (
            self._publishers,
            self._subscriptions,
            self._clients,
            self._services,
            self._timers,
            self._guards,
        ):
            while entities:
                entities.pop(0).destroy()
        self._waitables.clear()
        self.__destroyed = True
        current = _state.state()
        if self in current.nodes:
            current.nodes.remove(self)
        if self._executor is not None:
            self._executor.remove_node(self)
        self._wake_executor()

    def __enter__(self) -> Node:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.destroy_node()

    # ------------------------------------------------------------------ graph
    def _graph(self) -> list[Any]:
        return _state.runtime().current_graph()

    def _count_on_graph(self, bus_topic: str, *, subscribers: bool) -> int:
        """Endpoints on a topic: other processes' (from the run's graph, one per process) and
        this process's own, one per publisher or subscription."""
        own_label = _state.runtime().info.node_name
        count = 0
        for topic in self._graph():
            if topic.name == bus_topic:
                names = topic.subscribers if subscribers else topic.publishers
                count += sum(1 for name in names if name != own_label)
        count += _state.state().local_count(bus_topic, subscribers=subscribers)
        return count

    def _expanded_bus_topic(self, topic_name: str, kind: str = "topic name") -> str:
        return bus_name(self._resolve(topic_name, kind, only_expand=True))

    def count_publishers(self, topic_name: str) -> int:
        return self._count_on_graph(self._expanded_bus_topic(topic_name), subscribers=False)

    def count_subscribers(self, topic_name: str) -> int:
        return self._count_on_graph(self._expanded_bus_topic(topic_name), subscribers=True)

    def count_services(self, service_name: str) -> int:
        from sandbox.services import request_topic

        name = request_topic(self._expanded_bus_topic(service_name, "service name"))
        return self._count_on_graph(name, subscribers=True)

    def count_clients(self, service_name: str) -> int:
        from sandbox.services import request_topic

        name = request_topic(self._expanded_bus_topic(service_name, "service name"))
        return self._count_on_graph(name, subscribers=False)

    def get_topic_names_and_types(self, no_demangle: bool = False) -> list[tuple[str, list[str]]]:
        found: dict[str, set[str]] = {}
        for topic in self._graph():
            if not is_internal(topic.name):
                found.setdefault("/" + topic.name, set()).add(topic.type)
        for bus_topic, type_name in _state.state().local_topics():
            found.setdefault("/" + bus_topic, set()).add(type_name)
        return [(name, sorted(types)) for name, types in sorted(found.items())]

    def get_service_names_and_types(self) -> list[tuple[str, list[str]]]:
        found: dict[str, set[str]] = {}
        for service in _state.state().local_services():
            found.setdefault(service.srv_name, set()).add(service._type_name)
        from sandbox.services import REQUEST_PREFIX

        for topic in self._graph():
            if topic.name.startswith(REQUEST_PREFIX) and topic.subscribers:
                found.setdefault("/" + topic.name[len(REQUEST_PREFIX) :], set())
        return [(name, sorted(types)) for name, types in sorted(found.items())]

    def get_node_names_and_namespaces(self) -> list[tuple[str, str]]:
        current = _state.state()
        own_label = current.runtime.info.node_name
        found = {(node.get_name(), node.get_namespace()) for node in current.nodes}
        for topic in self._graph():
            for label in (*topic.publishers, *topic.subscribers):
                if label not in (own_label, "robot", "run"):
                    namespace, _, name = ("/" + label.strip("/")).rpartition("/")
                    found.add((name, namespace or "/"))
        return sorted(found)

    def get_node_names(self) -> list[str]:
        return [name for name, _ in self.get_node_names_and_namespaces()]

    def get_fully_qualified_node_names(self) -> list[str]:
        return [
            namespace + ("" if namespace.endswith("/") else "/") + name
            for name, namespace in self.get_node_names_and_namespaces()
        ]

    # ------------------------------------------------------------------ parameters
    def declare_parameter(
        self, name: str, value: Any = None, descriptor: Any = None, ignore_override: bool = False
    ) -> Parameter:
        return self._parameters.declare_parameter(name, value, descriptor, ignore_override)

    def declare_parameters(
        self, namespace: str, parameters: list[tuple[Any, ...]], ignore_override: bool = False
    ) -> list[Parameter]:
        return self._parameters.declare_parameters(namespace, parameters, ignore_override)

    def undeclare_parameter(self, name: str) -> None:
        self._parameters.undeclare(name)

    def has_parameter(self, name: str) -> bool:
        return self._parameters.has(name)

    def get_parameter(self, name: str) -> Parameter:
        return self._parameters.get(name)

    def get_parameter_or(self, name: str, alternative_value: Parameter | None = None) -> Parameter:
        return self._parameters.get_or(name, alternative_value)

    def get_parameters(self, names: list[str]) -> list[Parameter]:
        if not all(isinstance(name, str) for name in names):
            raise TypeError("All names must be instances of type str")
        return [self.get_parameter(name) for name in names]

    def get_parameters_by_prefix(self, prefix: str) -> dict[str, Parameter]:
        return self._parameters.by_prefix(prefix)

    def get_parameter_type(self, name: str) -> Any:
        return self._parameters.type_of(name)

    def get_parameter_types(self, names: list[str]) -> list[Any]:
        if not all(isinstance(name, str) for name in names):
            raise TypeError("All names must be instances of type str")
        return [self._parameters.type_of(name) for name in names]

    def set_parameters(self, parameter_list: list[Parameter]) -> list[Any]:
        return self._parameters.set_parameters(parameter_list)

    def set_parameters_atomically(self, parameter_list: list[Parameter]) -> Any:
        return self._parameters.set_atomically(parameter_list)

    def describe_parameter(self, name: str) -> Any:
        return self._parameters.describe(name)

    def describe_parameters(self, names: list[str]) -> list[Any]:
        return [self._parameters.describe(name) for name in names]

    def set_descriptor(self, name: str, descriptor: Any, alternative_value: Any = None) -> Any:
        return self._parameters.set_descriptor(name, descriptor, alternative_value)

    def list_parameters(self, prefixes: list[str], depth: int) -> Any:
        return self._parameters.list_parameters(prefixes, depth)

    def add_on_set_parameters_callback(self, callback: Callable[[list[Parameter]], Any]) -> None:
        self._parameters.on_set.insert(0, callback)

    def remove_on_set_parameters_callback(self, callback: Callable[[list[Parameter]], Any]) -> None:
        self._parameters.on_set.remove(callback)

    def add_pre_set_parameters_callback(self, callback: Callable[[list[Parameter]], Any]) -> None:
        self._parameters.pre_set.insert(0, callback)

    def remove_pre_set_parameters_callback(
        self, callback: Callable[[list[Parameter]], Any]
    ) -> None:
        self._parameters.pre_set.remove(callback)

    def add_post_set_parameters_callback(self, callback: Callable[[list[Parameter]], Any]) -> None:
        self._parameters.post_set.insert(0, callback)

    def remove_post_set_parameters_callback(
        self, callback: Callable[[list[Parameter]], Any]
    ) -> None:
        self._parameters.post_set.remove(callback)


def _flat_launch_params(params: dict[str, Any]) -> dict[str, Any]:
    """NodeInfo.params as ROS 2 parameter names: nested dicts dotted, a leading `~` or `/`
    (a ROS 1 habit) dropped."""
    flat = ros2_args.flatten(params)
    return {name.lstrip("~/").replace("/", "."): value for name, value in flat.items()}
