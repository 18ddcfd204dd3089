"""An action server's goal bookkeeping (sandbox/action_goals.py): rcl_action's state machine
and cancel policy."""

from __future__ import annotations

import pytest

from sandbox.action_goals import (
    ZERO_UUID,
    ActionGoals,
    CancelCode,
    GoalEvent,
    GoalStatus,
    GoalTransitionError,
)


def uuid(n: int) -> bytes:
    return bytes([n]) * 16


def test_a_goal_runs_accepted_executing_succeeded_and_refuses_more():
    goals = ActionGoals()
    goal = goals.accept(uuid(1), 100, "request")
    assert goal.status is GoalStatus.ACCEPTED
    goal.update(GoalEvent.EXECUTE)
    waiting = goals.finish(goal, GoalEvent.SUCCEED, "result")
    assert waiting == [] and goal.status is GoalStatus.SUCCEEDED and goal.result == "result"
    with pytest.raises(GoalTransitionError, match="SUCCEEDED; it cannot take ABORT"):
        goal.update(GoalEvent.ABORT)
    with pytest.raises(GoalTransitionError, match="already sent"):
        goals.accept(uuid(1), 200, "again")


def test_cancel_goes_through_canceling_and_ends_canceled():
    goals = ActionGoals()
    goal = goals.accept(uuid(1), 100, None)
    goal.update(GoalEvent.EXECUTE)
    code, canceling = goals.cancel(uuid(1), 0)
    assert code is CancelCode.NONE and canceling == [goal]
    assert goal.status is GoalStatus.CANCELING
    with pytest.raises(GoalTransitionError):
        goal.update(GoalEvent.EXECUTE)
    goals.finish(goal, GoalEvent.CANCELED, None, "canceled by the client")
    assert goal.status is GoalStatus.CANCELED and goal.status.terminal
    # A second cancel of the same goal: it has ended.
    assert goals.cancel(uuid(1), 0) == (CancelCode.GOAL_TERMINATED, [])
    assert goals.cancel(uuid(9), 0) == (CancelCode.UNKNOWN_GOAL_ID, [])


def test_cancel_policies_by_id_and_stamp():
    goals = ActionGoals()
    early, middle, late = (
        goals.accept(uuid(n), stamp, None) for n, stamp in ((1, 10), (2, 20), (3, 30))
    )
    # zero id, a stamp: every goal accepted at or before it
    code, canceling = goals.cancel(ZERO_UUID, 20)
    assert code is CancelCode.NONE and canceling == [early, middle]
    # an id and a stamp: that goal and those at or before the stamp (the others are canceling)
    code, canceling = goals.cancel(uuid(3), 5)
    assert canceling == [late]
    # zero id, zero stamp: everything still cancelable - nothing left
    assert goals.cancel(ZERO_UUID, 0) == (CancelCode.REJECTED, [])
    fresh = goals.accept(uuid(4), 40, None)
    assert goals.cancel(ZERO_UUID, 0) == (CancelCode.NONE, [fresh])


def test_result_requests_wait_for_the_end_and_unknown_goals_answer_at_once():
    goals = ActionGoals()
    goal = goals.accept(uuid(1), 1, None)
    goal.update(GoalEvent.EXECUTE)
    assert goals.result_request(uuid(1), "caller-a") == (False, None)
    assert goals.result_request(uuid(1), "caller-b") == (False, None)
    assert goals.result_request(uuid(7), "caller-c") == (True, None)  # unknown: answer now
    assert uuid(7) not in goals.waiting
    assert goals.finish(goal, GoalEvent.ABORT, "r", "no path") == ["caller-a", "caller-b"]
    assert goals.result_request(uuid(1), "caller-d") == (True, goal)  # ended: answered now
    assert goals.status_list() == [(uuid(1), 1, GoalStatus.ABORTED)]
    assert goals.active() == []


def test_cancelable_selects_without_changing_states() -> None:
    goals = ActionGoals()
    first = goals.accept(uuid(1), 10, "a")
    goals.accept(uuid(2), 20, "b").update(GoalEvent.EXECUTE)
    code, selected = goals.cancelable(ZERO_UUID, 0)
    assert code is CancelCode.NONE and [g.uuid for g in selected] == [uuid(1), uuid(2)]
    assert [g.status for g in goals.goals.values()] == [GoalStatus.ACCEPTED, GoalStatus.EXECUTING]
    first.update(GoalEvent.EXECUTE)
    first.update(GoalEvent.SUCCEED)
    assert goals.cancelable(uuid(1), 0) == (CancelCode.GOAL_TERMINATED, [])
    assert goals.cancelable(uuid(9), 0) == (CancelCode.UNKNOWN_GOAL_ID, [])
