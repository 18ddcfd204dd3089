"""Every ROS 2 type name RoboDojo knows, by package and kind, and the sentences for the rest.

A service ``pkg/srv/X`` brings the messages ``X_Request``, ``X_Response`` and ``X_Event``; an
action ``pkg/action/X`` brings ``X_Goal``, ``X_Result``, ``X_Feedback``, the services
``X_SendGoal`` and ``X_GetResult`` (with their messages) and ``X_FeedbackMessage``: the types
rosidl generates for them (ros2/rosidl, ``rosidl_parser/definition.py``: ``Service``,
``Action``; the event message since Iron's service introspection, REP 2012).
"""

from __future__ import annotations

from functools import cache

from ._definitions import ACTIONS, MESSAGES, SERVICES

MSG, SRV, ACTION = "msg", "srv", "action"
KINDS = (MSG, SRV, ACTION)


def _service_messages(name: str, request: str, response: str) -> dict[str, str]:
    return {
        f"{name}_Request": request,
        f"{name}_Response": response,
        f"{name}_Event": (
            f"service_msgs/ServiceEventInfo info\n{name}_Request[<=1] request\n"
            f"{name}_Response[<=1] response"
        ),
    }


@cache
def all_messages() -> dict[str, str]:
    """Every message type's own text, services' and actions' messages included."""
    messages = dict(MESSAGES)
    for name, (request, response) in SERVICES.items():
        messages.update(_service_messages(name, request, response))
    for name, (goal, result, feedback) in ACTIONS.items():
        messages[f"{name}_Goal"] = goal
        messages[f"{name}_Result"] = result
        messages[f"{name}_Feedback"] = feedback
        uuid = "unique_identifier_msgs/UUID goal_id"
        send = (f"{uuid}\n{name}_Goal goal", "bool accepted\nbuiltin_interfaces/Time stamp")
        messages.update(_service_messages(f"{name}_SendGoal", *send))
        get = (uuid, f"int8 status\n{name}_Result result")
        messages.update(_service_messages(f"{name}_GetResult", *get))
        messages[f"{name}_FeedbackMessage"] = f"{uuid}\n{name}_Feedback feedback"
    return messages


@cache
def packages() -> tuple[str, ...]:
    return tuple(sorted({name.split("/", 1)[0] for name in (*all_messages(), *SERVICES, *ACTIONS)}))


@cache
def names(package: str, kind: str) -> tuple[str, ...]:
    """Short names a ``<package>.<kind>`` Python module holds, as rosidl generates them.

    ``pkg.msg``: the messages; ``pkg.srv``: the services (their Request/Response are
    attributes of the service class); ``pkg.action``: the actions.
    """
    table = {MSG: MESSAGES, SRV: SERVICES, ACTION: ACTIONS}[kind]
    prefix = f"{package}/{kind}/"
    return tuple(sorted(n[len(prefix) :] for n in table if n.startswith(prefix)))


def close_matches(word: str, candidates: list[str] | tuple[str, ...]) -> list[str]:
    import difflib  # only on the error path

    by_lower = {candidate.lower(): candidate for candidate in candidates}
    found = difflib.get_close_matches(word.lower(), list(by_lower), n=3, cutoff=0.6)
    return [by_lower[lower] for lower in found]


def unknown_type_sentence(type_name: str, kind: str = MSG) -> str:
    """Why ``pkg/<kind>/Name`` is not a type RoboDojo provides, and what is close."""
    noun = {MSG: "message", SRV: "service", ACTION: "action"}[kind]
    parts = type_name.split("/")
    if len(parts) != 3 or not all(parts):
        example = {MSG: "std_msgs/msg/String", SRV: "std_srvs/srv/SetBool"}.get(
            kind, "example_interfaces/action/Fibonacci"
        )
        return (
            f"ROS 2 {noun} type {type_name!r} must be written 'package/{kind}/Name', "
            f"e.g. {example!r}"
        )
    package, _, name = parts
    if package not in packages():
        return (
            f"unknown {noun} type {type_name!r}: RoboDojo has no ROS 2 package {package!r}; "
            f"the packages are {', '.join(packages())}"
        )
    getter = {MSG: "get_message_class", SRV: "get_service_class", ACTION: "get_action_class"}
    for other in KINDS:
        if name in names(package, other) and other != kind:
            full = f"{package}/{other}/{name}"
            articled = {MSG: "a message", SRV: "a service", ACTION: "an action"}
            what, asked = articled[other], articled[kind]
            parts = ""
            if other == SRV and kind == MSG:
                parts = f" (its messages are {full}_Request and {full}_Response)"
            elif other == ACTION and kind == MSG:
                parts = f" (its messages are {full}_Goal, {full}_Result and {full}_Feedback)"
            return f"{full} is {what}, not {asked}{parts}: use {getter[other]}({full!r})"
    known = names(package, kind)
    hints = [f"{package}/{kind}/{match}" for match in close_matches(name, known)]
    suggestion = f" (did you mean {' or '.join(hints)}?)" if hints else ""
    listing = ", ".join(known) if known else f"none ({package} has no {noun}s)"
    return f"unknown {noun} type {type_name!r}{suggestion}; {package}'s {noun}s: {listing}"
