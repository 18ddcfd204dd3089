"""The goals of one ROS 2 action server, as rcl_action keeps them: each goal's state machine, the
cancel policy, the status list and the results a client asks for.

Pure bookkeeping (no messages, no clock of its own), shared by both sides of the sandbox wall:
the built-in navigation server (server/runs/nav2_server.py) and rclpy.action's ActionServer in
student code (sandbox/ros_compat2/rclpy/action/server.py) turn requests into calls here and what
comes back into replies.

Sources (facts, not code): rcl_action's goal state machine (goal_state_machine.c: which event
moves which state), action_msgs/msg/GoalStatus (the status numbers), action_msgs/srv/CancelGoal
(the four cancel policies by goal id and stamp, and the return codes), rclpy/action/server.py
(an unknown goal's result request is answered at once with STATUS_UNKNOWN; a known one waits for
the goal to end).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import IntEnum

ZERO_UUID = bytes(16)


class GoalStatus(IntEnum):
    """action_msgs/msg/GoalStatus.STATUS_*."""

    UNKNOWN = 0
    ACCEPTED = 1
    EXECUTING = 2
    CANCELING = 3
    SUCCEEDED = 4
    CANCELED = 5
    ABORTED = 6

    @property
    def terminal(self) -> bool:
        return self in (GoalStatus.SUCCEEDED, GoalStatus.CANCELED, GoalStatus.ABORTED)


class GoalEvent(IntEnum):
    EXECUTE = 0
    CANCEL_GOAL = 1
    SUCCEED = 2
    ABORT = 3
    CANCELED = 4


# rcl_action's transition table: (state, event) -> next state; anything else is refused.
_TRANSITIONS: dict[tuple[GoalStatus, GoalEvent], GoalStatus] = {
    (GoalStatus.ACCEPTED, GoalEvent.EXECUTE): GoalStatus.EXECUTING,
    (GoalStatus.ACCEPTED, GoalEvent.CANCEL_GOAL): GoalStatus.CANCELING,
    (GoalStatus.EXECUTING, GoalEvent.CANCEL_GOAL): GoalStatus.CANCELING,
    (GoalStatus.EXECUTING, GoalEvent.SUCCEED): GoalStatus.SUCCEEDED,
    (GoalStatus.EXECUTING, GoalEvent.ABORT): GoalStatus.ABORTED,
    (GoalStatus.CANCELING, GoalEvent.CANCELED): GoalStatus.CANCELED,
    (GoalStatus.CANCELING, GoalEvent.SUCCEED): GoalStatus.SUCCEEDED,
    (GoalStatus.CANCELING, GoalEvent.ABORT): GoalStatus.ABORTED,
}


class CancelCode(IntEnum):
    """action_msgs/srv/CancelGoal.Response.ERROR_*."""

    NONE = 0
    REJECTED = 1
    UNKNOWN_GOAL_ID = 2
    GOAL_TERMINATED = 3


class GoalTransitionError(ValueError):
    """An event the goal's state does not allow (rcl_action: RCL_RET_ACTION_GOAL_EVENT_INVALID)."""


@dataclass
class Goal:
    """One accepted goal: its id, when it was accepted [ns], its request, state and result."""

    uuid: bytes
    stamp_ns: int
    request: object
    status: GoalStatus = GoalStatus.ACCEPTED
    result: object = None
    message: str = ""  # why it ended, in a sentence (aborts and cancels)

    def update(self, event: GoalEvent) -> None:
        nxt = _TRANSITIONS.get((self.status, event))
        if nxt is None:
            raise GoalTransitionError(
                f"goal {self.uuid.hex()} is {self.status.name}; it cannot take {event.name}"
            )
        self.status = nxt


@dataclass
class ActionGoals:
    """Every goal one action server has accepted (terminal ones included: rcl_action keeps them
    until their result expires, 15 minutes by default - longer than any run), in order."""

    goals: dict[bytes, Goal] = field(default_factory=dict)
    # result requests waiting for their goal to end: uuid -> callers' reply handles
    waiting: dict[bytes, list[object]] = field(default_factory=dict)

    def accept(self, uuid: bytes, stamp_ns: int, request: object) -> Goal:
        if uuid in self.goals:
            raise GoalTransitionError(f"goal {uuid.hex()} was already sent to this server")
        goal = Goal(uuid, stamp_ns, request)
        self.goals[uuid] = goal
        return goal

    def active(self) -> list[Goal]:
        return [g for g in self.goals.values() if not g.status.terminal]

    def cancel(self, uuid: bytes, stamp_ns: int) -> tuple[CancelCode, list[Goal]]:
        """The goals a CancelGoal request selects, moved to CANCELING, and the return code."""
        code, canceling = self.cancelable(uuid, stamp_ns)
        for goal in canceling:
            goal.update(GoalEvent.CANCEL_GOAL)
        return code, canceling

    def cancelable(self, uuid: bytes, stamp_ns: int) -> tuple[CancelCode, list[Goal]]:
        """The goals a CancelGoal request selects and the return code, with no state changed
        (rclpy asks its cancel callback about each before moving it to CANCELING).

        Zero id and zero stamp: every goal. Zero id, a stamp: every goal accepted at or before
        it. An id, zero stamp: that goal. An id and a stamp: that goal and every goal accepted
        at or before the stamp. Only ACCEPTED and EXECUTING goals can be canceled."""
        selected = []
        for goal in self.goals.values():
            by_id = uuid != ZERO_UUID and goal.uuid == uuid
            by_stamp = stamp_ns != 0 and goal.stamp_ns <= stamp_ns
            everything = uuid == ZERO_UUID and stamp_ns == 0
            if by_id or by_stamp or everything:
                selected.append(goal)
        canceling = [g for g in selected if g.status in (GoalStatus.ACCEPTED, GoalStatus.EXECUTING)]
        if canceling:
            return CancelCode.NONE, canceling
        if uuid != ZERO_UUID and uuid not in self.goals:
            return CancelCode.UNKNOWN_GOAL_ID, []
        if uuid != ZERO_UUID:
            return CancelCode.GOAL_TERMINATED, []
        return CancelCode.REJECTED, []

    def finish(self, goal: Goal, event: GoalEvent, result: object, message: str = "") -> list:
        """End a goal (SUCCEED, ABORT or CANCELED) with its result; returns the reply handles
        of the result requests that waited for it."""
        goal.update(event)
        goal.result, goal.message = result, message
        return self.waiting.pop(goal.uuid, [])

    def result_request(self, uuid: bytes, caller: object) -> tuple[bool, Goal | None]:
        """A GetResult request: (True, goal) if the goal has ended, (True, None) if no such
        goal exists (answer both now; the latter with STATUS_UNKNOWN), (False, None) while it
        runs (the caller is kept and handed back by `finish`)."""
        goal = self.goals.get(uuid)
        if goal is None or goal.status.terminal:
            return True, goal
        self.waiting.setdefault(uuid, []).append(caller)
        return False, None

    def status_list(self) -> list[tuple[bytes, int, GoalStatus]]:
        """(uuid, accepted stamp [ns], status) of every goal, for the status topic."""
        return [(g.uuid, g.stamp_ns, g.status) for g in self.goals.values()]
