"""The state a launch description is visited in (launch.LaunchContext): launch configurations
and their scopes, locals such as the current launch file, and what the visit has found.

Scopes are launch's: GroupAction(scoped=True) pushes a copy of the configurations and pops it
after its actions; IncludeLaunchDescription does not scope (its arguments stay set after it,
as in ros2 launch); locals (the current file) are pushed around every sub-entity."""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from typing import Any

from sandbox.launch2.errors import LaunchError, Site


@dataclass
class LaunchContext:
    """launch.LaunchContext as far as a launch file can see it, plus the visit's findings."""

    workdir: str  # the workspace's copy in the job's working directory (absolute)
    launch_configurations: dict[str, Any] = field(default_factory=dict)
    argv: list[str] = field(default_factory=list)
    _configuration_stack: list[dict[str, Any]] = field(default_factory=list)
    _locals_stack: list[dict[str, Any]] = field(default_factory=lambda: [{}])
    declared_arguments: set[str] = field(default_factory=set)
    nodes: list[Any] = field(default_factory=list)  # ros_actions.PlannedNode, in launch order
    notes: list[str] = field(default_factory=list)
    include_depth: int = 0

    # ------------------------------------------------------------------ launch's API
    @property
    def locals(self) -> Any:
        values = self.get_locals_as_dict()

        class _Locals:
            def __getattr__(self, key: str) -> Any:
                if key not in values:
                    raise AttributeError(f"context.locals has no '{key}'")
                return values[key]

        return _Locals()

    def get_locals_as_dict(self) -> dict[str, Any]:
        combined: dict[str, Any] = {}
        for layer in self._locals_stack:
            combined.update(layer)
        return combined

    def extend_locals(self, extensions: dict[str, Any]) -> None:
        self._locals_stack[-1].update(extensions)

    def perform_substitution(self, substitution: Any) -> str:
        return substitution.perform(self)

    # ------------------------------------------------------------------ scopes
    def push_locals(self) -> None:
        self._locals_stack.append({})

    def pop_locals(self) -> None:
        self._locals_stack.pop()

    def push_launch_configurations(self) -> None:
        self._configuration_stack.append(self.launch_configurations)
        self.launch_configurations = {
            key: list(value) if isinstance(value, list) else value
            for key, value in self.launch_configurations.items()
        }

    def pop_launch_configurations(self) -> None:
        if not self._configuration_stack:
            raise LaunchError(
                "PopLaunchConfigurations without a PushLaunchConfigurations before it"
            )
        self.launch_configurations = self._configuration_stack.pop()

    # ------------------------------------------------------------------ the workspace
    def relative(self, path: str, site: Site | None, what: str) -> str:
        """`path` (absolute or relative to the working directory) as a workspace-relative
        path; LaunchError if it points outside the workspace."""
        absolute = os.path.normpath(os.path.join(self.workdir, path))
        inside = os.path.relpath(absolute, self.workdir)
        if inside == ".." or inside.startswith(".." + os.sep):
            raise LaunchError(
                f"{what} '{path}' is outside your workspace; build paths from "
                "get_package_share_directory('<your package>') or os.path.dirname(__file__)",
                site,
            )
        return inside.replace(os.sep, "/")

    def note(self, site: Site | None, text: str) -> None:
        where = f"{site.filename}, line {site.line}: " if site and site.line else ""
        self.notes.append(where + text)
