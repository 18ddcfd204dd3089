"""Module-level `__getattr__` for the stand-ins of sandbox/launch_shim: a name ROS 2 has and
RoboDojo's launch reader does not is an ImportError with a sentence saying so."""

from __future__ import annotations

from collections.abc import Callable


def missing(module: str) -> Callable[[str], object]:
    def __getattr__(name: str) -> object:
        if name.startswith("__"):
            raise AttributeError(name)
        raise ImportError(
            f"{module}.{name} is not available in RoboDojo's launch reader, which reads "
            "nodes, arguments, parameters, remappings, namespaces, groups, includes and "
            "conditions; write the launch file with those"
        )

    return __getattr__
