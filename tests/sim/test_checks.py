"""The definition checkers (server.sim.checks): every registered robot and world passes, and a
broken definition is refused with a sentence per problem."""

from __future__ import annotations

import dataclasses
import math
from typing import ClassVar

import pytest

from sandbox.msgs.std_msgs import Bool
from server.sim import check_robot, check_world
from server.sim.checks import (
    DefinitionError,
    WorldDefinitionError,
    registry_problems,
    robot_problems,
    world_problems,
)
from server.sim.registry import robot_ids
from server.sim.robots.base import RobotGeometry, RobotLimits
from server.sim.robots.crop_rover import CropRover
from server.sim.robots.crowbot import CrowBot
from server.sim.sensors.button import Button
from server.sim.world import LightSource, Spawn, WorldError, load_world, world_ids


@pytest.mark.parametrize("robot_id", robot_ids())
def test_every_registered_robot_passes(robot_id: str) -> None:
    check_robot(robot_id)
    assert robot_problems(CrowBot()) == []


@pytest.mark.parametrize("world_id", world_ids())
def test_every_packaged_world_passes(world_id: str) -> None:
    check_world(world_id)
    check_world(load_world(world_id))


def test_the_registry_as_a_whole_is_sound() -> None:
    assert registry_problems() == []


class _NotBuildable:
    """A message class whose constructor needs an argument."""

    _type = "std_msgs/Broken"

    def __init__(self, value: int) -> None:
        self.value = value


class BrokenBot(CrowBot):
    """A CrowBot with one mistake of every kind the checker should find."""

    geometry = RobotGeometry(
        body_radius_m=0.06,
        wheel_radius_m=0.02,
        track_m=-0.08,  # negative size
        length_m=0.12,
        width_m=0.12,
        height_m=0.06,
        body_offset_x_m=0.1,  # axle outside the body
    )
    limits = RobotLimits(max_linear_m_s=0.1, max_angular_rad_s=math.nan)
    commands: ClassVar = {
        "Control": CrowBot.commands["Control"],
        "Horn": (_NotBuildable, "sounds the horn"),  # cannot be built empty
        "Lamp": (Bool, "switches the lamp"),  # apply_command does not know it
        "bad topic": (Bool, ""),  # not a ROS name, no description
    }
    frames: ClassVar = {"base_link": (0.0, 0.0, 0.0), "sonar": (0.05, 0.0)}

    def build_sensors(self):
        sensors = super().build_sensors()
        sensors["Button"] = Button(0.0)  # no rate
        stamped = Button(20.0)
        stamped.frame_id = "camera"  # a frame it does not declare
        sensors["Stamped"] = stamped
        return sensors

    def apply_command(self, topic, message, state, motors, time_s) -> None:
        if topic == "Lamp":
            raise KeyError(topic)
        super().apply_command(topic, message, state, motors, time_s)


def test_a_broken_robot_is_refused_with_a_sentence_per_problem() -> None:
    with pytest.raises(DefinitionError) as caught:
        check_robot(BrokenBot())
    text = str(caught.value)
    assert text.startswith("robot 'crowbot' has ")
    expected = [
        "geometry.track_m must be a positive size [m], got -0.08",
        "geometry.body_offset_x_m must put the wheel axle inside the body",
        "limits.max_angular_rad_s must be a positive speed, got nan",
        "sensor topic 'Button' has rate 0.0 Hz; give a finite rate above 0",
        "sensor topic 'Stamped' has no description",
        "command topic 'Horn': std_msgs/Broken() does not build",
        "command topic 'Lamp': apply_command raised KeyError",
        "command topic 'bad topic' is not a ROS name",
        "command topic 'bad topic' has no description",
        "sensor frame 'base_link' is one the run provides",
        "sensor frame 'sonar' must be (x [m], y [m], yaw [rad])",
        "sensor topic 'Stamped' stamps frame_id 'camera', which is not among its frames",
    ]
    for sentence in expected:
        assert sentence in text, sentence
    assert len(robot_problems(BrokenBot())) == text.count("\n- ") == len(expected)


def test_a_robot_that_refuses_an_empty_command_with_a_sentence_is_sound() -> None:
    # The crowbot's Leds refuses data = [] with CommandError: that is an answer, not a bug.
    assert not any("'Leds'" in problem for problem in robot_problems(CrowBot()))


def test_a_spawn_the_large_robot_does_not_fit_is_refused() -> None:
    world = load_world("crop_rows")
    rover = CropRover.geometry.body_radius_m
    plant_x, plant_y, plant_radius = world.circles[0]
    # Half the rover's radius from a plant's surface: room for a crowbot, not for the rover.
    tight = Spawn("tight", plant_x + plant_radius + rover / 2, plant_y, 0.0)
    broken = dataclasses.replace(world, spawns=(world.spawns[0], tight))
    problems = world_problems(broken)
    assert any(
        p.startswith("world 'crop_rows': spawn 'tight' leaves ")
        and f"around the body of 'crop_rover', which needs {rover:.3f} m" in p
        for p in problems
    ), problems


def test_a_broken_world_is_refused_with_a_sentence_per_problem() -> None:
    office = load_world("office")
    lamp = LightSource("lamp", 99.0, 1.0, -0.1, 0.0, True)
    broken = dataclasses.replace(
        office,
        spawns=(office.spawns[0], Spawn(office.spawns[0].name, -5.0, 1.0, 0.0)),
        lights=(lamp,),
        ambient_light=1.5,
        robots=("turtlebot", "hovercraft"),
    )
    with pytest.raises(WorldError) as caught:
        check_world(broken)
    assert isinstance(caught.value, WorldDefinitionError)
    assert isinstance(caught.value, DefinitionError)
    text = str(caught.value)
    assert text.startswith("world 'office' has 6 problems:\n- ")
    for sentence in (
        "spawn names must be unique, got ['start', 'start']",
        "spawn 'start' at (-5.0, 1.0) is outside",
        "light 'lamp' at (99.0, 1.0) is outside",
        "light 'lamp' needs intensity > 0 and height z >= 0 [m], got 0.0 and -0.1",
        "ambient_light must lie within [0, 1], got 1.5",
        "unknown robot id 'hovercraft'",
    ):
        assert sentence in text, sentence


def test_a_world_without_spawns_or_robots_says_what_to_add() -> None:
    broken = dataclasses.replace(load_world("wall_approach"), spawns=(), robots=())
    problems = world_problems(broken)
    assert "world 'wall_approach': has no spawn; add at least one start pose" in problems
    assert "world 'wall_approach': declares no robots; list the robot ids it suits" in problems
