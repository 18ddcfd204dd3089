"""The fair queue for a real robot."""

from __future__ import annotations

import pytest

from server.hardware.queue import QueueError, RobotQueue, SlotState


def queue() -> RobotQueue:
    return RobotQueue("crowbot-1", slot_s=100.0, start_within_s=30.0)


def test_first_come_first_served_with_one_place_each():
    q = queue()
    assert q.join("ada", 0).state is SlotState.OFFERED
    q.join("bob", 1)
    q.join("ada", 2)  # asking again keeps the place, adds none
    assert [p.user_id for p in q.places] == ["ada", "bob"]
    assert q.position("bob") == 2 and q.position("eve") is None


def test_only_the_offered_student_may_start_and_the_next_follows_at_the_end():
    q = queue()
    q.join("ada", 0)
    q.join("bob", 0)
    with pytest.raises(QueueError, match="number 2 in the queue"):
        q.start("bob", "run-b", 1)
    q.start("ada", "run-a", 1)
    assert q.estimated_wait_s("bob", 51) == pytest.approx(50.0)
    q.finish("run-a", 60)
    assert q.place_of("bob").state is SlotState.OFFERED


def test_a_slot_not_started_in_time_passes_to_the_next():
    q = queue()
    q.join("ada", 0)
    q.join("bob", 0)
    q.tick(31)
    assert q.place_of("ada") is None and q.place_of("bob").state is SlotState.OFFERED
    assert q.passed_on == 1


def test_a_run_over_its_slot_is_reported_for_stopping():
    q = queue()
    q.join("ada", 0)
    q.start("ada", "run-a", 0)
    assert q.tick(99) == []
    assert q.tick(100) == ["run-a"]


def test_the_instructor_moves_skips_and_takes_the_robot_out_of_service():
    q = queue()
    for user in ("ada", "bob", "cy", "dee"):
        q.join(user, 0)
    q.move("dee", 1, 1)  # first among those waiting (ada holds the offer)
    assert [p.user_id for p in q.places] == ["ada", "dee", "bob", "cy"]
    q.set_in_service(False, 2)
    assert all(p.state is SlotState.WAITING for p in q.places)
    q.skip("ada", 3)
    assert q.place_of("dee").state is SlotState.WAITING  # out of service: nobody offered
    q.set_in_service(True, 4)
    assert q.place_of("dee").state is SlotState.OFFERED
    with pytest.raises(QueueError):
        q.move("dee", 2, 5)  # offered, not waiting
    described = q.describe(5)
    assert [p["position"] for p in described["places"]] == [1, 2, 3]
    assert described["places"][2]["estimated_wait_s"] == 200.0
