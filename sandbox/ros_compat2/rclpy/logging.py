"""rclpy.logging: named loggers and their levels (rclpy/logging.py)."""

from __future__ import annotations

from .impl.logging_severity import LoggingSeverity
from .impl.rcutils_logger import RcutilsLogger, effective_level
from .impl.rcutils_logger import _levels as _logger_levels

__all__ = [
    "LoggingSeverity",
    "RcutilsLogger",
    "get_logger",
    "get_logger_effective_level",
    "get_logger_level",
    "get_logging_severity_from_string",
    "set_logger_level",
]

_root_logger = RcutilsLogger()


def get_logger(name: str) -> RcutilsLogger:
    if not name:
        raise ValueError("Logger name must not be empty.")
    return _root_logger.get_child(name)


def initialize() -> None:
    pass


def shutdown() -> None:
    pass


def clear_config() -> None:
    _logger_levels().clear()


def set_logger_level(name: str, level: int | LoggingSeverity, detailed_error: bool = False) -> None:
    _logger_levels()[name] = LoggingSeverity(level)


def get_logger_effective_level(name: str) -> LoggingSeverity:
    return effective_level(name)


def get_logger_level(name: str) -> LoggingSeverity:
    return LoggingSeverity(_logger_levels().get(name, LoggingSeverity.UNSET))


def get_logging_severity_from_string(log_severity: str) -> LoggingSeverity:
    try:
        return LoggingSeverity[log_severity.upper()]
    except KeyError:
        raise RuntimeError(f"Failed to get log severity from name '{log_severity}'") from None
