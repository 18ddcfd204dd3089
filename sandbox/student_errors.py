"""Turn an exception from student code into a `NodeError` that points at the student's lines.

The traceback keeps only frames from the student's file (compiled under `Load.filename`, with
its source registered in linecache so the lines show). When the exception was raised inside a
library the student called (numpy, the rospy shim, the stdlib), the last student frame is the
line that made the call, followed by a note naming the library, then `TypeError: ...`.
"""

from __future__ import annotations

import linecache
import os
import sysconfig
import traceback

from sandbox.protocol import NodeError

_SANDBOX_DIR = os.path.dirname(os.path.abspath(__file__))
_ROS_COMPAT_DIRS = (
    os.path.join(_SANDBOX_DIR, "ros_compat"),  # rospy and the ROS 1 packages
    os.path.join(_SANDBOX_DIR, "ros_compat2"),  # rclpy and the ROS 2 packages
)
# Student-facing libraries of the sandbox outside ros_compat (shared by both ROS versions),
# named as the student imports them.
_SHARED_LIBRARIES = {
    os.path.join(_SANDBOX_DIR, "tf2"): "tf2_ros",
    os.path.join(_SANDBOX_DIR, "transformations"): "transformations",
}
_STDLIB_DIR = sysconfig.get_paths()["stdlib"]


class StepError(Exception):
    """A step-API contract broken by the student's module (bad RATE_HZ, bad return value).

    `line` is where to look: the `def step` or the assignment in question.
    """

    def __init__(self, message: str, line: int | None) -> None:
        super().__init__(message)
        self.line = line


def register_source(filename: str, code: str) -> None:
    """Let tracebacks show the student's source lines (the file need not exist on disk)."""
    lines = code.splitlines(keepends=True)
    # mtime None: linecache.checkcache() leaves the entry alone.
    linecache.cache[filename] = (len(code), None, lines, filename)


def summary(error: NodeError) -> str:
    """One line for Exited.reason: `ZeroDivisionError: division by zero (line 7)`."""
    where = f" (line {error.line})" if error.line is not None else ""
    return f"{error.type}: {error.message}{where}"


def from_syntax_error(error: SyntaxError, filename: str) -> NodeError:
    lines = traceback.format_exception_only(type(error), error)
    return NodeError(
        type=type(error).__name__,
        message=str(error.msg),
        filename=filename,
        line=error.lineno,
        traceback="".join(lines),
    )


def from_step_error(error: StepError, filename: str) -> NodeError:
    where = f'  File "{filename}", line {error.line}\n' if error.line is not None else ""
    return NodeError(
        type="StepError",
        message=str(error),
        filename=filename,
        line=error.line,
        traceback=f"{where}StepError: {error}\n",
    )


def _library_of(path: str) -> str:
    """A short name for where a non-student frame lives: 'numpy', 'rospy', 'json', ..."""
    path = os.path.abspath(path)
    for marker in ("site-packages", "dist-packages"):
        parts = path.split(os.sep)
        if marker in parts:
            rest = parts[parts.index(marker) + 1 :]
            return rest[0].removesuffix(".py") if rest else marker
    for compat_dir in _ROS_COMPAT_DIRS:
        if path.startswith(compat_dir + os.sep):
            return os.path.relpath(path, compat_dir).split(os.sep)[0]
    for directory, library in _SHARED_LIBRARIES.items():
        if path.startswith(directory + os.sep):
            return library
    if path.startswith(_SANDBOX_DIR + os.sep):
        return "the RoboDojo node host"
    if path.startswith(_STDLIB_DIR + os.sep):
        return os.path.relpath(path, _STDLIB_DIR).split(os.sep)[0].removesuffix(".py")
    return os.path.basename(path)


def from_exception(error: BaseException, filename: str) -> NodeError:
    if isinstance(error, SyntaxError) and error.filename == filename:
        return from_syntax_error(error, filename)
    if isinstance(error, StepError):
        return from_step_error(error, filename)
    frames = traceback.extract_tb(error.__traceback__)
    mine = [frame for frame in frames if frame.filename == filename]
    text = ""
    if mine:
        text = "Traceback (most recent call last):\n"
        text += "".join(traceback.StackSummary.from_list(mine).format())
    if frames and frames[-1].filename != filename and mine:
        text += f"  (raised inside {_library_of(frames[-1].filename)})\n"
    text += "".join(traceback.format_exception_only(type(error), error))
    message = str(error)
    if isinstance(error, KeyError) and len(error.args) == 1:
        message = repr(error.args[0])
    return NodeError(
        type=type(error).__name__,
        message=message,
        filename=filename,
        line=mine[-1].lineno if mine else None,
        traceback=text,
    )
