"""A run's lifecycle: an explicit state enum with checked transitions (Starlette's
WebSocketState habit), and the reason every end carries."""

from __future__ import annotations

from enum import StrEnum


class RunState(StrEnum):
    CREATED = "created"
    STARTING = "starting"  # nodes loading, the clock not yet running
    RUNNING = "running"
    PAUSED = "paused"  # lockstep only: the clock holds
    STOPPING = "stopping"  # nodes shutting down, recording closing
    FINISHED = "finished"  # duration reached, or every node ended by itself
    FAILED = "failed"  # a node raised or was killed, the robot left the map, an internal fault
    INTERRUPTED = "interrupted"  # stopped by a person or the server

    @property
    def is_end(self) -> bool:
        return self in (RunState.FINISHED, RunState.FAILED, RunState.INTERRUPTED)


_ALLOWED = {
    RunState.CREATED: {RunState.STARTING, RunState.FAILED, RunState.INTERRUPTED},
    RunState.STARTING: {RunState.RUNNING, RunState.STOPPING},
    RunState.RUNNING: {RunState.PAUSED, RunState.STOPPING},
    RunState.PAUSED: {RunState.RUNNING, RunState.STOPPING},
    RunState.STOPPING: {RunState.FINISHED, RunState.FAILED, RunState.INTERRUPTED},
    RunState.FINISHED: set(),
    RunState.FAILED: set(),
    RunState.INTERRUPTED: set(),
}


class RunStateError(RuntimeError):
    """A transition the lifecycle does not allow (a bug in the caller, not the student)."""


def check_transition(current: RunState, new: RunState) -> None:
    if new not in _ALLOWED[current]:
        allowed = ", ".join(sorted(_ALLOWED[current])) or "nothing (it has ended)"
        raise RunStateError(f"a {current} run cannot become {new}; from {current}: {allowed}")
