"""The typed run commands (server/runs/commands.py): every command crosses JSON and comes back the
same, and what is wrong with a command is said in a sentence naming the field."""

from __future__ import annotations

import dataclasses
import json
import typing

import pytest

from server.runs import commands
from server.runs.commands import (
    COMMANDS,
    Button,
    CommandError,
    EmergencyStop,
    Goal,
    InjectFault,
    Light,
    Pause,
    Resume,
    Stop,
    Teleop,
    command_dict,
    parse_command,
)
from server.runs.faults import FaultKind

ONE_OF_EACH = [
    Stop("stopped by the user: lunch"),
    EmergencyStop("an instructor"),
    Pause(),
    Resume(),
    Button(pressed=False),
    Light(1.5, -0.25, "lamp"),
    Light(0.5, 0.5),
    Goal(1.0, 2.0, 0.5),
    Teleop("left", pressed=False),
    InjectFault(FaultKind.DROP_TOPIC, "Distance", 2.5),
    InjectFault(FaultKind.STALL_MOTORS, duration_s=0.5),
]


def test_every_command_is_in_the_table_and_the_examples():
    union = set(typing.get_args(commands.RunCommand))
    assert set(COMMANDS.values()) == union
    assert {type(c) for c in ONE_OF_EACH} == union
    assert all(COMMANDS[cls.op] is cls for cls in union)


@pytest.mark.parametrize("command", ONE_OF_EACH, ids=lambda c: type(c).__name__)
def test_a_command_round_trips_through_json(command):
    wire = json.loads(json.dumps(command_dict(command), allow_nan=False))
    assert wire["op"] == command.op
    again = parse_command(wire)
    assert again == command and type(again) is type(command)
    assert command_dict(again) == wire


def test_a_command_cannot_be_changed_once_made():
    goal = Goal(1.0, 2.0)
    with pytest.raises(dataclasses.FrozenInstanceError):
        goal.x = 5.0  # type: ignore[misc]
    with pytest.raises(dataclasses.FrozenInstanceError):
        EmergencyStop("the user").who = "an instructor"  # type: ignore[misc]


@pytest.mark.parametrize(
    ("data", "words"),
    [
        ([1, 2], "a command is a JSON object"),
        ({"op": "warp"}, "unknown op 'warp'; ops: stop, estop"),
        ({"x": 1}, "unknown op None"),
        ({"op": "goal", "x": 1}, "'goal' needs y"),
        ({"op": "goal", "x": 1, "y": 2, "z": 3}, "it does not know z"),
        ({"op": "estop", "who": "the instructor", "why": 1}, "it does not know why"),
        ({"op": "pause", "now": True}, "'pause' takes no fields; it does not know now"),
        ({"op": "light", "x": "far", "y": 0}, "'x' must be a finite number for 'light'"),
        ({"op": "goal", "x": 1, "y": float("nan")}, "'y' must be a finite number"),
        ({"op": "goal", "x": True, "y": 0}, "'x' must be a finite number"),
        ({"op": "button", "pressed": "yes"}, "'pressed' must be true or false"),
        ({"op": "teleop", "key": "warp"}, "teleop knows the keys up, down, left, right"),
        ({"op": "stop", "reason": "x" * 501}, "at most 500 characters"),
        ({"op": "fault", "kind": "melt"}, "a fault is one of drop_topic"),
        ({"op": "fault", "kind": "drop_topic"}, "needs the topic it affects"),
        ({"op": "fault", "kind": "stall_motors", "duration_s": 0}, "a positive number of s"),
    ],
)
def test_a_bad_command_is_refused_with_a_sentence(data, words):
    with pytest.raises(CommandError) as refused:
        parse_command(data)
    assert words in str(refused.value)


def test_a_request_id_is_not_part_of_the_command():
    assert parse_command({"id": 7, "op": "button", "pressed": True}) == Button(True)
    with pytest.raises(CommandError, match="does not know id"):
        parse_command({"id": 7, "op": "resume"}, ignore=())


def test_an_emergency_stop_says_who_in_its_reason():
    assert EmergencyStop("an instructor").reason == "emergency stop by an instructor"
