"""The ir_scout_avoidance exercise: the reference's topic graph is the paper's Fig. 8, the sensor
node's ADC -> cm conversion inverts the simulated ranger, and the stuck metric measures what it
says. (Reference passes on five seeds and starter fails: tests/exercises/test_exercises.py.)"""

from __future__ import annotations

import dataclasses
import importlib.util
import itertools
import sys
from types import SimpleNamespace

import numpy as np
import pytest

from sandbox import bwrap
from sandbox.host import ROS_COMPAT_DIR
from sandbox.launcher import Launcher
from server.exercises.grading import reference_nodes, run_spec
from server.exercises.ir_scout import IR_SCOUT_AVOIDANCE, longest_stuck_s
from server.exercises.model import EXERCISE_DIR
from server.runs.run import Run
from server.runs.state import RunState
from server.sim.sensors.adc import ADC_MAX_COUNT
from server.sim.sensors.ir_ranger import ADC_FULL_SCALE_V, DIVIDER_RATIO, volts_for_range

# Fig. 8: topic -> (publishers, subscribers); "robot" is the simulated ir_scout.
PAPER_GRAPH = {
    "ir_adc": (["robot"], ["sensor"]),
    "distance_detect": (["sensor"], ["servo"]),
    "dist_detect": (["servo"], ["dc_motor"]),
    "dist_detect_right": (["servo"], ["compare_distance"]),
    "dist_detect_left": (["servo"], ["compare_distance"]),
    "direction": (["compare_distance"], ["dc_motor"]),
    "forward": (["dc_motor"], ["servo"]),
    "servo_angle": (["servo"], []),
    "motor_command": (["dc_motor"], []),
}


@pytest.fixture(scope="module")
def reference_run(tmp_path_factory):
    problem = bwrap.probe()
    if problem:
        pytest.fail(f"the exercise tests need bubblewrap: {problem} (./scripts/test installs it)")
    launcher = Launcher(pool_size=4)
    try:
        exercise = dataclasses.replace(IR_SCOUT_AVOIDANCE, duration_s=30.0)
        spec = run_spec(exercise, reference_nodes(exercise), seed=1)
        yield Run(spec, launcher, tmp_path_factory.mktemp("ir_scout") / "run").execute()
    finally:
        launcher.close()


def test_reference_nodes_are_the_papers_four():
    assert [name for name, _ in IR_SCOUT_AVOIDANCE.reference] == [
        "sensor",
        "servo",
        "compare_distance",
        "dc_motor",
    ]


@pytest.mark.slow
def test_reference_topic_graph_is_the_papers_fig_8(reference_run):
    assert reference_run.state is RunState.FINISHED, reference_run.reason
    topics = {topic["name"]: topic for topic in reference_run.graph["topics"]}
    for name, (publishers, subscribers) in PAPER_GRAPH.items():
        topic = topics[name]
        assert (sorted(topic["publishers"]), sorted(topic["subscribers"])) == (
            publishers,
            subscribers,
        ), name
        # In 30 s from the start the robot meets the first crate: every topic carries messages.
        assert topic["messages"] > 0, name


@pytest.fixture(scope="module")
def sensor_node():
    """The reference sensor node loaded as a module (its rospy calls sit in main())."""
    added = ROS_COMPAT_DIR not in sys.path
    if added:
        sys.path.insert(0, ROS_COMPAT_DIR)
    before = set(sys.modules)
    path = EXERCISE_DIR / "reference" / "ir_scout_sensor.py"
    spec = importlib.util.spec_from_file_location("ir_scout_sensor_under_test", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    yield module
    for name in set(sys.modules) - before:  # the rospy shim stays out of other tests
        del sys.modules[name]
    if added:
        sys.path.remove(ROS_COMPAT_DIR)


def simulated_count(distance_cm: float) -> int:
    """The AIN0 count the simulated ranger gives for a target at `distance_cm`, noise-free."""
    volts_at_pin = volts_for_range(distance_cm) * DIVIDER_RATIO
    return round(volts_at_pin / ADC_FULL_SCALE_V * ADC_MAX_COUNT)


@pytest.mark.parametrize("distance_cm", [10.0, 15.0, 30.0, 50.0, 80.0])
def test_adc_to_cm_inverts_the_simulated_ranger(sensor_node, distance_cm):
    # One ADC count is 0.88 mV at the sensor; at 80 cm that is ~0.4 cm of range.
    assert sensor_node.adc_count_to_cm(simulated_count(distance_cm)) == pytest.approx(
        distance_cm, rel=0.01
    )


def test_adc_to_cm_nothing_in_range_is_far(sensor_node):
    assert sensor_node.adc_count_to_cm(0) == sensor_node.FAR_CM
    assert sensor_node.adc_count_to_cm(simulated_count(200.0)) == sensor_node.FAR_CM
    # The 0.30 V the sensor gives with nothing in front reads beyond the 80 cm it can see.
    no_target = round(0.30 * DIVIDER_RATIO / ADC_FULL_SCALE_V * ADC_MAX_COUNT)
    assert sensor_node.adc_count_to_cm(no_target) > 100.0


def test_adc_to_cm_falls_as_the_count_rises(sensor_node):
    # From count 300 (0.26 V at the sensor, ~140 cm) up: below it the reading is capped.
    distances = [sensor_node.adc_count_to_cm(count) for count in range(300, ADC_MAX_COUNT, 50)]
    assert all(a > b for a, b in itertools.pairwise(distances))


def pose_evidence(times, xs, ys):
    return SimpleNamespace(pose_t=np.array(times), pose_x=np.array(xs), pose_y=np.array(ys))


def test_longest_stuck_is_the_longest_stay_within_5_cm():
    times = np.arange(0.0, 20.0, 0.04)
    # Drives 2 s at 0.12 m/s, stands 12 s (turning in place counts), drives on.
    xs = np.where(times < 2.0, times * 0.12, np.where(times < 14.0, 0.24, 0.24 + (times - 14.0)))
    stuck = longest_stuck_s(pose_evidence(times, xs, np.zeros_like(times)))
    # The stay starts when the robot is 5 cm before the stop and ends 5 cm after it.
    assert stuck == pytest.approx(12.0 + 0.05 / 0.12 + 0.05, abs=0.1)


def test_longest_stuck_counts_a_stay_until_the_end():
    times = np.arange(0.0, 30.0, 0.04)
    xs = np.minimum(times, 1.0)
    # From x = 0.95 m (t = 0.95 s) to the last pose at t = 29.96 s.
    assert longest_stuck_s(pose_evidence(times, xs, np.zeros_like(times))) == pytest.approx(
        29.01, abs=0.05
    )


def test_longest_stuck_without_poses_has_nothing_to_judge():
    with pytest.raises(ValueError, match="no pose"):
        longest_stuck_s(pose_evidence([], [], []))
