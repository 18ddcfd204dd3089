"""A launch file that cannot be run as written: a sentence, and where in which launch file.

Every action and substitution remembers the launch-file line that created it (`caller_site`),
so an error found while the description is visited (a missing argument, an unknown package)
names the line the student wrote, not a line of ours."""

from __future__ import annotations

import sys
from dataclasses import dataclass

# Workspace-relative names of the launch files compiled so far (their code objects carry them).
LAUNCH_FILES: set[str] = set()


@dataclass(frozen=True, slots=True)
class Site:
    """A place in a launch file: its workspace-relative name and a 1-based line."""

    filename: str
    line: int | None


def caller_site() -> Site | None:
    """The innermost launch-file line on the current call stack (None outside one)."""
    frame = sys._getframe(1)
    while frame is not None:
        if frame.f_code.co_filename in LAUNCH_FILES:
            return Site(frame.f_code.co_filename, frame.f_lineno)
        frame = frame.f_back
    return None


class LaunchError(Exception):
    """The launch file is wrong; str() is the sentence, `site` where (when known)."""

    def __init__(self, message: str, site: Site | None = None) -> None:
        super().__init__(message)
        self.site = site if site is not None else caller_site()


class SubstitutionFailure(LaunchError):
    """A substitution cannot be performed (launch.substitutions.SubstitutionFailure)."""


class InvalidConditionExpressionError(LaunchError):
    """A condition's text is not true/false/1/0 (launch.conditions's error of that name)."""


class PackageNotFoundError(KeyError):
    """ament_index_python's error for a package that is not installed; here: not in the
    workspace. A KeyError as in ament_index_python, with a sentence for str()."""

    def __init__(self, message: str) -> None:
        super().__init__(message)
        self.site = caller_site()

    def __str__(self) -> str:
        return str(self.args[0])
