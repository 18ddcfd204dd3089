"""turtlebot_stanley_ros2: the thesis's Nav2 form (a Stanley service the controller server calls,
goals sent with BasicNavigator) graded as the ROS 1 exercise, on the realtime clock too (the
lockstep clock is test_exercises.py's five seeds)."""

from __future__ import annotations

import dataclasses

import pytest

from sandbox.protocol import Clock
from server.exercises import turtlebot
from server.exercises.grading import grade, reference_nodes


def test_graded_exactly_as_the_ros1_exercise():
    ros1, ros2 = turtlebot.TURTLEBOT_STANLEY, turtlebot.TURTLEBOT_STANLEY_ROS2
    assert [(c.name, c.threshold) for c in ros2.checks] == [
        (c.name, c.threshold) for c in ros1.checks
    ]
    assert ros2.builtin_nodes == ("map_server", "localization", "nav2")
    assert ros2.params["controller_frequency"] == 5.0  # the thesis's Stanley rate


@pytest.mark.slow
def test_reference_passes_on_the_realtime_clock(launcher, tmp_path):
    exercise = dataclasses.replace(turtlebot.TURTLEBOT_STANLEY_ROS2, seeds=(3,))
    result = grade(exercise, reference_nodes(exercise), launcher, tmp_path, Clock.REALTIME)
    failed = [(c.name, c.per_seed, c.threshold) for c in result.checks if not c.passed]
    assert result.passed, (failed, [r["reason"] for r in result.runs])
    log = (tmp_path / "run0-seed3" / "logs").glob("nav2*")
    text = "".join(path.read_text() for path in log)
    assert text.count("navigate_to_pose: heading to") == 3  # three NavigateToPose goals
