"""Faults an instructor (or an exercise) injects into a running robot, to see how a controller
copes: a sensor that goes silent, a sensor that repeats itself, wheels that stop answering.
Each lasts a given time and then clears by itself."""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum

from sandbox.protocol import Envelope


class FaultKind(StrEnum):
    DROP_TOPIC = "drop_topic"  # a sensor goes silent
    FREEZE_TOPIC = "freeze_topic"  # a sensor repeats its last reading
    STALL_MOTORS = "stall_motors"  # the wheels stop answering commands


@dataclass(frozen=True, slots=True)
class Fault:
    kind: FaultKind
    topic: str | None
    until_ns: int


class Faults:
    """The faults active in one run, applied to what the robot publishes."""

    def __init__(self) -> None:
        self.active: list[Fault] = []
        self._frozen: dict[str, Envelope] = {}

    def add(self, fault: Fault) -> None:
        self.active.append(fault)

    def expire(self, now_ns: int) -> None:
        if self.active:
            self.active = [f for f in self.active if f.until_ns > now_ns]

    def motors_stalled(self) -> bool:
        return any(f.kind is FaultKind.STALL_MOTORS for f in self.active)

    def filter(self, envelope: Envelope) -> Envelope | None:
        """What subscribers get instead of `envelope`: None (dropped), the frozen first
        reading, or the envelope itself."""
        for fault in self.active:
            if fault.topic != envelope.topic:
                continue
            if fault.kind is FaultKind.DROP_TOPIC:
                return None
            if fault.kind is FaultKind.FREEZE_TOPIC:
                return self._frozen.setdefault(envelope.topic, envelope)
        self._frozen.pop(envelope.topic, None)
        return envelope
