"""Sharing the robots: one run per robot at a time, students wait in a fair queue.

Fair: a student holds at most one place per robot (asking again keeps the place, it does not
add one); places are served in order. When the robot frees up, the first student gets a slot:
they must start their run within `start_within_s` or the slot passes to the next; a run may
use the robot for at most `slot_s`. The instructor can move a student, skip one, and take a
robot out of service (the queue waits; nobody is lost). Every place shows its position and an
estimated start (the slots before it, each at most `slot_s`).

Pure: every call gets the time, so the tests drive it; the web service calls it under a lock.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import StrEnum

DEFAULT_SLOT_S = 300.0  # [s] a hardware run's longest stretch on the robot (5 minutes)
DEFAULT_START_WITHIN_S = 60.0  # [s] a student whose turn came starts within this, or loses it


class QueueError(ValueError):
    """A request the queue cannot take; the message says what to do."""


class SlotState(StrEnum):
    WAITING = "waiting"  # in the queue
    OFFERED = "offered"  # the robot is free for them: start before `offered_until_s`
    RUNNING = "running"  # their run has the robot


@dataclass
class Place:
    user_id: str
    joined_s: float
    state: SlotState = SlotState.WAITING
    offered_until_s: float | None = None
    started_s: float | None = None
    run_id: str | None = None


@dataclass
class RobotQueue:
    robot: str
    slot_s: float = DEFAULT_SLOT_S
    start_within_s: float = DEFAULT_START_WITHIN_S
    in_service: bool = True
    places: list[Place] = field(default_factory=list)
    passed_on: int = 0  # slots not started in time

    # --------------------------------------------------------------------------- students
    def join(self, user_id: str, now_s: float) -> Place:
        for place in self.places:
            if place.user_id == user_id:
                return place  # one place per student: asking again keeps it
        place = Place(user_id, now_s)
        self.places.append(place)
        self.tick(now_s)
        return place

    def leave(self, user_id: str, now_s: float) -> None:
        self.places = [p for p in self.places if p.user_id != user_id]
        self.tick(now_s)

    def start(self, user_id: str, run_id: str, now_s: float) -> Place:
        """The student's run takes the robot: only with the slot offered to them."""
        self.tick(now_s)
        place = self.place_of(user_id)
        if place is None:
            raise QueueError(f"you are not in the queue for {self.robot}; join it first")
        if place.state is not SlotState.OFFERED:
            position = self.position(user_id)
            raise QueueError(
                f"it is not your turn on {self.robot} yet: you are number {position} in the "
                f"queue, expected to start in about {self.estimated_wait_s(user_id, now_s):.0f} s"
            )
        place.state, place.started_s, place.run_id = SlotState.RUNNING, now_s, run_id
        return place

    def finish(self, run_id: str, now_s: float) -> None:
        """A run on the robot ended (any way): the robot goes to the next student."""
        self.places = [p for p in self.places if p.run_id != run_id]
        self.tick(now_s)

    # --------------------------------------------------------------------------- time
    def tick(self, now_s: float) -> list[str]:
        """Pass on slots not started in time, offer the robot when it is free; returns the run
        ids over their slot time (the caller stops those runs)."""
        over = [
            p.run_id
            for p in self.places
            if p.state is SlotState.RUNNING and p.started_s is not None and p.run_id is not None
            and now_s - p.started_s >= self.slot_s
        ]  # fmt: skip
        for place in list(self.places):
            if place.state is SlotState.OFFERED and now_s > (place.offered_until_s or 0.0):
                self.places.remove(place)  # their turn passed; they may join again
                self.passed_on += 1
        if self.in_service and not any(p.state is not SlotState.WAITING for p in self.places):
            waiting = [p for p in self.places if p.state is SlotState.WAITING]
            if waiting:
                waiting[0].state = SlotState.OFFERED
                waiting[0].offered_until_s = now_s + self.start_within_s
        return over

    # --------------------------------------------------------------------------- instructor
    def move(self, user_id: str, position: int, now_s: float) -> None:
        """Put a waiting student at `position` (1 = next) among those waiting."""
        place = self.place_of(user_id)
        if place is None or place.state is not SlotState.WAITING:
            raise QueueError("only a student who is waiting can be moved")
        waiting = [p for p in self.places if p.state is SlotState.WAITING and p is not place]
        index = max(0, min(len(waiting), position - 1))
        waiting.insert(index, place)
        self.places = [p for p in self.places if p.state is not SlotState.WAITING] + waiting
        self.tick(now_s)

    def skip(self, user_id: str, now_s: float) -> None:
        """Take a student out of the queue (their turn goes to the next)."""
        if self.place_of(user_id) is None:
            raise QueueError("that student is not in this queue")
        self.leave(user_id, now_s)

    def set_in_service(self, in_service: bool, now_s: float) -> None:
        self.in_service = in_service
        if not in_service:  # an offered slot waits; nobody loses their place
            for place in self.places:
                if place.state is SlotState.OFFERED:
                    place.state, place.offered_until_s = SlotState.WAITING, None
        self.tick(now_s)

    # --------------------------------------------------------------------------- views
    def place_of(self, user_id: str) -> Place | None:
        return next((p for p in self.places if p.user_id == user_id), None)

    def position(self, user_id: str) -> int | None:
        """1 = has or is offered the robot next; None = not in the queue."""
        for index, place in enumerate(self.places, start=1):
            if place.user_id == user_id:
                return index
        return None

    def estimated_wait_s(self, user_id: str, now_s: float) -> float:
        """At most: the running slot's rest plus a whole slot for each place before theirs."""
        wait = 0.0
        for place in self.places:
            if place.user_id == user_id:
                return wait
            if place.state is SlotState.RUNNING and place.started_s is not None:
                wait += max(0.0, self.slot_s - (now_s - place.started_s))
            else:
                wait += self.slot_s
        raise QueueError("that student is not in this queue")

    def describe(self, now_s: float) -> dict:
        return {
            "robot": self.robot,
            "in_service": self.in_service,
            "slot_s": self.slot_s,
            "start_within_s": self.start_within_s,
            "passed_on": self.passed_on,
            "places": [
                {
                    "position": index,
                    "user_id": p.user_id,
                    "state": str(p.state),
                    "run_id": p.run_id,
                    "offered_until_s": p.offered_until_s,
                    "estimated_wait_s": round(self.estimated_wait_s(p.user_id, now_s), 1),
                }
                for index, p in enumerate(self.places, start=1)
            ],
        }
