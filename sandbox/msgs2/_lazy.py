"""ROS 2 ``<pkg>.msg``, ``<pkg>.srv`` and ``<pkg>.action`` modules whose classes are built on use.

What rosidl_generator_py's package ``__init__.py`` files export (ros2/rosidl_python,
``generate_py_impl.py``: one ``from <pkg>.<kind>._<name> import <Name>`` per interface): the
messages in ``msg``, the services in ``srv`` (their ``_Request``/``_Response`` are attributes of
the service class), the actions in ``action``. Here nothing is built until asked for (PEP 562
module ``__getattr__``), so ``from std_msgs.msg import String`` costs one class.

A student module calls ``install(globals(), "std_msgs", "msg")``; a name the package lacks
fails with a sentence (ImportError for ``from m import Name``, as Python would raise, with the
close names and the ones it has).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from sandbox.msgs._lazy import MissingTypeError, _called_by_import_from

from ._catalog import KINDS, close_matches, names, packages


def module_names(package: str, kind: str) -> tuple[str, ...]:
    """The names ``<package>.<kind>`` exports: ``module_names("std_srvs", "srv")``."""
    if kind not in KINDS:
        raise ValueError(f"kind must be one of {KINDS}, got {kind!r}")
    return names(package, kind)


def getter(kind: str) -> Callable[[str], Any]:
    """``get_message_class``, ``get_service_class`` or ``get_action_class`` for ``kind``."""
    from . import get_action_class, get_message_class, get_service_class

    return {"msg": get_message_class, "srv": get_service_class, "action": get_action_class}[kind]


def missing_name_sentence(package: str, kind: str, name: str, module: str) -> str:
    """Why ``module`` has no ``name``, and where it is or what is close."""
    for other in KINDS:
        if other != kind and name in names(package, other):
            return f"{package}/{other}/{name} is not in {module}: import it from {package}.{other}"
    hints = [
        f"{other_package}.{kind}.{name}"
        for other_package in packages()
        if other_package != package and name in names(other_package, kind)
    ]
    if kind == "srv" and name.endswith(("_Request", "_Response")):
        service = name.rsplit("_", 1)[0]
        hints.insert(0, f"{service}.{name.rsplit('_', 1)[1]} (from {module} import {service})")
    available = names(package, kind)
    hints += close_matches(name, available)
    suggestion = f" Did you mean {' or '.join(hints)}?" if hints else ""
    return (
        f"{module} has no type {name!r}.{suggestion} It holds: {', '.join(available)} "
        f"(the ROS 2 Jazzy {kind} types of {package} that RoboDojo provides)."
    )


def install(namespace: dict[str, Any], package: str, kind: str) -> None:
    """Give the module whose globals are ``namespace`` the ``kind`` types of ``package``."""
    module_name = namespace["__name__"]
    available = frozenset(module_names(package, kind))
    build = getter(kind)

    def __getattr__(name: str) -> Any:
        if name in available:
            value = namespace[name] = build(f"{package}/{kind}/{name}")  # later lookups skip us
            return value
        if name.startswith("_"):  # probes from pickle, inspect, doctest...
            raise MissingTypeError(f"module {module_name!r} has no attribute {name!r}", name=name)
        sentence = missing_name_sentence(package, kind, name, module_name)
        if _called_by_import_from():
            raise ImportError(sentence, name=module_name)
        raise MissingTypeError(sentence, name=name)

    def __dir__() -> list[str]:
        return sorted(available.union(namespace))

    namespace["__getattr__"] = __getattr__
    namespace["__dir__"] = __dir__
    namespace["__all__"] = sorted(available)
