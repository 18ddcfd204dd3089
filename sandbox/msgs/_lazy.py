"""Message modules whose classes are built on first use (PEP 562 module ``__getattr__``).

``sandbox.msgs.std_msgs`` and the student-facing ``std_msgs.msg`` hold no class until one is
asked for: ``from std_msgs.msg import Int32`` or ``std_msgs.msg.Int32`` builds it through
``get_message_class`` (so both modules hand out the same class) and keeps it in the module.
``dir()`` and ``__all__`` list every type without building any.

A name that does not exist fails with a sentence: ``ImportError`` for ``from m import Name``
(Python would otherwise replace any AttributeError by its own "cannot import name"), an
AttributeError subclass for ``m.Name``.
"""

from __future__ import annotations

import opcode
import sys
from collections.abc import Callable
from typing import Any

from ._catalog import is_service, missing_name_sentence, names
from ._core import get_message_class
from ._services import get_service_class

_IMPORT_FROM = opcode.opmap["IMPORT_FROM"]


class MissingTypeError(AttributeError):
    """A message module has no type of that name; the message says what it does have."""


def _called_by_import_from() -> bool:
    """Whether the frame that looked the attribute up is running ``from module import name``."""
    try:
        frame = sys._getframe(2)  # 0: here, 1: __getattr__, 2: whoever looked the name up
        return frame.f_code.co_code[frame.f_lasti] == _IMPORT_FROM
    except (ValueError, IndexError):  # no such frame (called from C at the top)
        return False


def install(namespace: dict[str, Any], package: str, kinds: tuple[str, ...]) -> None:
    """Give the module whose globals are ``namespace`` the types of ``package``'s ``kinds``.

    ``kinds`` is ``("msg",)`` for ``<pkg>.msg``, ``("srv",)`` for ``<pkg>.srv``, both for
    ``sandbox.msgs.<pkg>``.
    """
    module_name = namespace["__name__"]
    available = frozenset(name for kind in kinds for name in names(package, kind))

    def __getattr__(name: str) -> Any:
        if name in available:
            full_name = f"{package}/{name}"
            build: Callable[[str], Any] = (
                get_service_class if is_service(full_name) else get_message_class
            )
            value = namespace[name] = build(full_name)  # later lookups skip this function
            return value
        if name.startswith("_"):  # dunder probes from pickle, inspect, doctest...
            raise MissingTypeError(f"module {module_name!r} has no attribute {name!r}", name=name)
        sentence = missing_name_sentence(package, kinds, name, module_name)
        if _called_by_import_from():
            raise ImportError(sentence, name=module_name)
        raise MissingTypeError(sentence, name=name)

    def __dir__() -> list[str]:
        return sorted(available.union(namespace))

    namespace["__getattr__"] = __getattr__
    namespace["__dir__"] = __dir__
    namespace["__all__"] = sorted(available)
