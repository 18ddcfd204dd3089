"""Which type names exist, by package and kind, and the sentences for names that do not.

Answers from the definition table alone (``_definitions.py``), without building any class, so
``dir()`` of a message module and an error for a misspelt name cost no class construction.
A package's ``msg`` kind holds its messages (actions' messages included, as in ROS); its ``srv``
kind holds its services with their ``<Name>Request``/``<Name>Response`` messages, as a ROS 1
``<pkg>.srv`` Python module does.
"""

from __future__ import annotations

from functools import cache

from ._definitions import MESSAGES, SERVICES

MSG = "msg"
SRV = "srv"

_SERVICE_PARTS = frozenset(f"{name}{part}" for name in SERVICES for part in ("Request", "Response"))


@cache
def packages() -> tuple[str, ...]:
    """Every package with at least one type, sorted."""
    return tuple(sorted({name.split("/", 1)[0] for name in (*MESSAGES, *SERVICES)}))


@cache
def names(package: str, kind: str) -> tuple[str, ...]:
    """Short names in ``package``'s ``msg`` or ``srv`` module, sorted."""
    if kind == MSG:
        full = [t for t in MESSAGES if t not in _SERVICE_PARTS]
    else:
        full = [*SERVICES, *_SERVICE_PARTS]
    prefix = package + "/"
    return tuple(sorted(t[len(prefix) :] for t in full if t.startswith(prefix)))


def kinds(package: str) -> tuple[str, ...]:
    """``("msg",)``, ``("srv",)`` or both: the modules ROS 1 has for ``package``."""
    return tuple(kind for kind in (MSG, SRV) if names(package, kind))


def is_service(type_name: str) -> bool:
    return type_name in SERVICES


def close_matches(word: str, candidates: tuple[str, ...] | list[str]) -> list[str]:
    """Up to three candidates that look like ``word`` (case-insensitive), best first."""
    import difflib  # only on the error path: it costs a millisecond of every node's start-up

    by_lower = {candidate.lower(): candidate for candidate in candidates}
    found = difflib.get_close_matches(word.lower(), list(by_lower), n=3, cutoff=0.6)
    return [by_lower[lower] for lower in found]


def _either(options: list[str]) -> str:
    """``a``, ``a or b``, ``a, b or c``."""
    return options[0] if len(options) == 1 else f"{', '.join(options[:-1])} or {options[-1]}"


def _where_else(package: str, name: str) -> list[str]:
    """``pkg.kind`` modules other than ``package``'s that hold a type called ``name``."""
    return [
        f"{other}.{kind}"
        for other in packages()
        for kind in (MSG, SRV)
        if name in names(other, kind) and other != package
    ]


def missing_name_sentence(package: str, kinds: tuple[str, ...], name: str, module: str) -> str:
    """Why ``module`` (holding ``package``'s ``kinds``) has no ``name``, and what to use."""
    available = sorted({n for kind in kinds for n in names(package, kind)})
    for other_kind in {MSG, SRV} - set(kinds):
        if name in names(package, other_kind):
            what = "a service" if other_kind == SRV else "a message"
            return f"{package}/{name} is {what}: import it from {package}.{other_kind}"
    hints = [f"{other}.{name}" for other in _where_else(package, name)]
    hints += close_matches(name, available)
    suggestion = f" Did you mean {_either(hints)}?" if hints else ""
    return (
        f"{module} has no type {name!r}.{suggestion} It holds: {', '.join(available)} "
        f"(the ROS 1 noetic types of {package})."
    )


def unknown_type_sentence(type_name: str, kind: str = MSG) -> str:
    """Why ``"pkg/Name"`` is not a known message (or service) type, with what is."""
    noun = "message" if kind == MSG else "service"
    if type_name.count("/") != 1:
        return (
            f"{noun} type {type_name!r} must be written 'package/Name', e.g. "
            f"{'std_msgs/String' if kind == MSG else 'std_srvs/SetBool'!r}"
        )
    if kind == MSG and type_name in SERVICES:
        return (
            f"{type_name} is a service, not a message: its messages are {type_name}Request and "
            f"{type_name}Response, and get_service_class({type_name!r}) gives the service"
        )
    if kind == SRV and type_name in MESSAGES:
        return f"{type_name} is a message, not a service: use get_message_class({type_name!r})"
    package, name = type_name.split("/")
    if package not in packages():
        return (
            f"unknown {noun} type {type_name!r}: RoboDojo has no package {package!r}; known types "
            f"are those of {', '.join(packages())}"
        )
    full = [t for t in (MESSAGES if kind == MSG else SERVICES) if t.startswith(package + "/")]
    if not full:
        return f"unknown {noun} type {type_name!r}: {package} has no {noun}s"
    hints = [f"{other.split('.')[0]}/{name}" for other in _where_else(package, name)]
    short_names = [t[len(package) + 1 :] for t in full]
    hints += [f"{package}/{match}" for match in close_matches(name, short_names)]
    suggestion = f" (did you mean {_either(hints)}?)" if hints else ""
    return f"unknown {noun} type {type_name!r}{suggestion}; known types are: {', '.join(full)}"
