"""rclpy's logger (rclpy/impl/rcutils_logger.py), printing as rcutils' console output does:

    [INFO] [12.300000000] [talker]: Publishing: "Hello World: 3"

The time is the run's (seconds.nanoseconds of the node's clock). Severity filtering follows the
logger hierarchy (`talker.child` inherits `talker`'s level; the default is INFO, or the
`--log-level` of the command line). The filters once=, skip_first= and throttle_duration_sec=
keep their state per call site (file and line), as rclpy's do; a site that changes its
severity or filters between calls raises ValueError, as in rclpy. One difference: a throttled
site logs its first call at once (rclpy starts its throttle at clock time 0, which on a wall
clock is long past, but a run's clock starts at 0).
"""

from __future__ import annotations

import sys
from typing import Any

from .. import _state
from .logging_severity import LoggingSeverity

SEPARATOR = "."
_FILTERS = ("once", "throttle_duration_sec", "throttle_time_source_type", "skip_first")


def _levels() -> dict[str, int]:
    return _state.state().logger_levels


def effective_level(name: str) -> LoggingSeverity:
    levels = _levels()
    probe = name
    while True:
        level = levels.get(probe, LoggingSeverity.UNSET)
        if level != LoggingSeverity.UNSET:
            return LoggingSeverity(level)
        if not probe:
            return LoggingSeverity.INFO
        probe = probe.rpartition(SEPARATOR)[0]


def _site() -> tuple[str, int, str]:
    """The student's call site (file, line, function), past this module's frames."""
    frame = sys._getframe(1)
    while frame is not None and frame.f_code.co_filename == __file__:
        frame = frame.f_back  # type: ignore[assignment]
    if frame is None:
        return ("", 0, "")
    return (frame.f_code.co_filename, frame.f_lineno, frame.f_code.co_name)


class RcutilsLogger:
    def __init__(self, name: str = "") -> None:
        self.name = name
        self.contexts: dict[tuple[str, int, str], dict[str, Any]] = {}

    def __repr__(self) -> str:
        return f"RcutilsLogger(name={self.name!r})"

    def get_child(self, name: str) -> RcutilsLogger:
        if not name:
            raise ValueError("Child logger name must not be empty.")
        return RcutilsLogger(f"{self.name}{SEPARATOR}{name}" if self.name else name)

    def set_level(self, level: int | LoggingSeverity) -> None:
        _levels()[self.name] = LoggingSeverity(level)

    def get_effective_level(self) -> LoggingSeverity:
        return effective_level(self.name)

    def is_enabled_for(self, severity: int | LoggingSeverity) -> bool:
        return LoggingSeverity(severity) >= self.get_effective_level()

    def log(
        self,
        message: Any,
        severity: int | LoggingSeverity,
        name: str | None = None,
        **kwargs: Any,
    ) -> bool:
        """Print `message` at `severity` unless the level or a filter stops it; True if it
        printed."""
        unknown = sorted(set(kwargs) - set(_FILTERS))
        if unknown:
            raise TypeError(
                f"unexpected logging arguments {unknown}: the logger takes once=, skip_first=, "
                "throttle_duration_sec= and throttle_time_source_type="
            )
        if not isinstance(message, str):
            raise TypeError(
                f"the logger prints a str, got {type(message).__name__}: format it first, e.g. "
                "self.get_logger().info(f'distance: {distance}')"
            )
        if not self.is_enabled_for(severity):
            return False
        severity = LoggingSeverity(severity)
        name = self.name if name is None else name
        filters = tuple(
            key for key in ("throttle_duration_sec", "skip_first", "once") if kwargs.get(key)
        )
        site = _site()
        context = self.contexts.get(site)
        if context is None:
            context = {"name": name, "severity": severity, "filters": filters, **kwargs}
            context["logged_once"] = False
            context["skipped_first"] = False
            context["last_logged_ns"] = None
            self.contexts[site] = context
        else:
            if severity != context["severity"]:
                raise ValueError("Logger severity cannot be changed between calls.")
            if name != context["name"]:
                raise ValueError("Logger name cannot be changed between calls.")
            if filters != context["filters"]:
                raise ValueError("Requested logging filters cannot be changed between calls.")
            if any(context.get(key) != kwargs.get(key) for key in _FILTERS if key in kwargs):
                raise ValueError("Logging filter parameters cannot be changed between calls.")
        if not _passes(context, kwargs):
            return False
        _print(severity, name, message)
        return True

    def debug(self, message: Any, **kwargs: Any) -> bool:
        return self.log(message, LoggingSeverity.DEBUG, **kwargs)

    def info(self, message: Any, **kwargs: Any) -> bool:
        return self.log(message, LoggingSeverity.INFO, **kwargs)

    def warning(self, message: Any, **kwargs: Any) -> bool:
        return self.log(message, LoggingSeverity.WARN, **kwargs)

    def warn(self, message: Any, **kwargs: Any) -> bool:
        return self.log(message, LoggingSeverity.WARN, **kwargs)

    def error(self, message: Any, **kwargs: Any) -> bool:
        return self.log(message, LoggingSeverity.ERROR, **kwargs)

    def fatal(self, message: Any, **kwargs: Any) -> bool:
        return self.log(message, LoggingSeverity.FATAL, **kwargs)


def _passes(context: dict[str, Any], kwargs: dict[str, Any]) -> bool:
    """rclpy's filters in its order: throttle, skip_first, once."""
    if kwargs.get("throttle_duration_sec"):
        clock = kwargs.get("throttle_time_source_type")
        now = clock.now().nanoseconds if clock is not None else _state.now_ns()
        last = context["last_logged_ns"]
        if last is not None and now < last + kwargs["throttle_duration_sec"] * 1e9:
            return False
        context["last_logged_ns"] = now
    if kwargs.get("skip_first") and not context["skipped_first"]:
        context["skipped_first"] = True
        return False
    if kwargs.get("once"):
        if context["logged_once"]:
            return False
        context["logged_once"] = True
    return True


_SEVERITY_NAMES = {
    LoggingSeverity.DEBUG: "DEBUG",
    LoggingSeverity.INFO: "INFO",
    LoggingSeverity.WARN: "WARN",
    LoggingSeverity.ERROR: "ERROR",
    LoggingSeverity.FATAL: "FATAL",
}


def format_line(severity: LoggingSeverity, time_ns: int, name: str, message: str) -> str:
    """rcutils' default console format: `[{severity}] [{time}] [{name}]: {message}`."""
    seconds, nanoseconds = divmod(time_ns, 1_000_000_000)
    level = _SEVERITY_NAMES.get(severity, "INFO")
    return f"[{level}] [{seconds}.{nanoseconds:09d}] [{name}]: {message}"


def _print(severity: LoggingSeverity, name: str, message: str) -> None:
    print(format_line(severity, _state.now_ns(), name, message), flush=True)
