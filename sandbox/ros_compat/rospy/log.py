"""loginfo and friends, printed to the node's log stream in rospy's screen format:
`[INFO] [12.300000]: text` with the node's time."""

from __future__ import annotations

import sys
from typing import Any

from sandbox import runtime as _runtime

from .core import DEBUG, ERROR, FATAL, INFO, WARN

_LEVELS = {"DEBUG": DEBUG, "INFO": INFO, "WARN": WARN, "ERROR": ERROR, "FATAL": FATAL}


def _emit(level: str, msg: Any, args: tuple[Any, ...]) -> None:
    node = _runtime.current()
    if _LEVELS[level] < node.log_level:
        return
    text = str(msg) % args if args else str(msg)
    node.log(level, text)


def _call_site(level: str) -> tuple[str, int, str]:
    frame = sys._getframe(2)  # the student's line that called loginfo_throttle()/_once()
    return (frame.f_code.co_filename, frame.f_lineno, level)


def _make(level: str) -> tuple[Any, Any, Any]:
    def log(msg: Any, *args: Any, **kwargs: Any) -> None:
        _emit(level, msg, args)

    def log_throttle(period: float, msg: Any, *args: Any, **kwargs: Any) -> None:
        site = _call_site(level)
        node = _runtime.current()
        now = node.clock.now_ns()
        last = node.log_sites.get(site)
        if last is None or now - last >= round(float(period) * 1e9):
            node.log_sites[site] = now
            _emit(level, msg, args)

    def log_once(msg: Any, *args: Any, **kwargs: Any) -> None:
        site = ("once", *_call_site(level))
        node = _runtime.current()
        if site not in node.log_sites:
            node.log_sites[site] = 0
            _emit(level, msg, args)

    return log, log_throttle, log_once


logdebug, logdebug_throttle, logdebug_once = _make("DEBUG")
loginfo, loginfo_throttle, loginfo_once = _make("INFO")
logwarn, logwarn_throttle, logwarn_once = _make("WARN")
logerr, logerr_throttle, logerr_once = _make("ERROR")
logfatal, logfatal_throttle, logfatal_once = _make("FATAL")
logout = loginfo
logerror = logerr
