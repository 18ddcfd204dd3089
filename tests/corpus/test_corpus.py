"""ROS 1 course scripts run unchanged (issue 12): each script in tests/corpus/scripts/ is written
the way course material writes it, run through the real run engine and sandbox (server.runs.Run
with the real launcher, or `robodojo run --launch` for the launch file) on both clocks, and
judged on behaviour by its check in tests/corpus/checks.py. A case whose feature or fix has not
landed is a strict xfail naming it.
"""

from __future__ import annotations

import math
import re

import pytest

from sandbox.protocol import Clock
from tests.corpus.checks import (
    check_busy_approach,
    check_class_approach,
    check_crowbot_light,
    check_crowbot_pid,
    check_debug_topic,
    check_ir_scout_commands,
    check_launch,
    check_launch_with_args,
    check_odom_turn,
    check_params_default,
    check_params_set,
    check_reactive,
    check_remap,
    check_roslib_open_loop,
    check_rosrun_args,
    check_services,
    check_shutdown_hook,
    check_slow_neighbour,
    check_square,
    check_talker_listener,
    check_tb3_closest,
    check_tb3_obstacle_stop,
    check_tf2_distance,
    check_tf_listener,
    check_timer,
    check_wait_for_scan,
    check_wall_follower,
    check_waypoints,
    check_yaml_config,
)
from tests.corpus.harness import (
    SCRIPTS,
    Case,
    Node,
    run_case,
    run_scripts,
    start_realtime_runs,
)

# Realtime runs wait on the wall clock most of the time; this many share the machine at once.
REALTIME_RUNS_AT_ONCE = 3
FINISHED = ("finished: duration reached", "finished: every node ended")


# ------------------------------------------------------------------------------------- cases
CASES = (
    Case(
        "talker_listener",
        "crowbot",
        "wall_approach",
        3.0,
        check_talker_listener,
        nodes=(Node("listener.py"), Node("talker.py")),
    ),
    Case(
        "class_approach",
        "crowbot",
        "wall_approach",
        8.0,
        check_class_approach,
        nodes=(Node("class_approach.py"),),
    ),
    Case(
        "busy_approach",
        "crowbot",
        "wall_approach",
        5.0,
        check_busy_approach,
        nodes=(Node("busy_approach.py"),),
    ),
    Case(
        "tb3_wall_follower",
        "turtlebot3",
        "office",
        6.0,
        check_wall_follower,
        nodes=(Node("tb3_wall_follower.py"),),
        initial_pose=(2.6, 2.95, 0.0),
    ),
    Case(
        "square_time_now",
        "turtlebot",
        "office",
        9.0,
        check_square,
        nodes=(Node("square_time_now.py"),),
        spawn="start",
    ),
    Case(
        "timer_driver",
        "crowbot",
        "wall_approach",
        3.5,
        check_timer,
        nodes=(Node("timer_driver.py"),),
    ),
    Case(
        "services",
        "crowbot",
        "wall_approach",
        4.0,
        check_services,
        nodes=(Node("motor_server.py"), Node("motor_client.py")),
    ),
    Case(
        "params_default",
        "crowbot",
        "wall_approach",
        3.0,
        check_params_default,
        nodes=(Node("param_driver.py"),),
    ),
    Case(
        "params_set",
        "crowbot",
        "wall_approach",
        3.0,
        check_params_set,
        nodes=(Node("param_driver.py", params={"~speed": 0.1, "/robot_name": "crowbot_7"}),),
    ),
    Case(
        "rosrun_args",
        "crowbot",
        "wall_approach",
        3.5,
        check_rosrun_args,
        nodes=(Node("param_driver.py", args=("_speed:=0.1", "_stop_distance:=0.45")),),
    ),
    Case(
        "remap",
        "crowbot",
        "wall_approach",
        3.0,
        check_remap,
        nodes=(Node("remap_forward.py", remaps=(("cmd_vel", "Control"),)),),
    ),
    Case(
        "odom_turn_tf",
        "turtlebot",
        "office",
        5.0,
        check_odom_turn,
        nodes=(Node("odom_turn_tf.py"),),
        spawn="start",
    ),
    Case(
        "tf2_distance",
        "turtlebot3",
        "office",
        5.0,
        check_tf2_distance,
        nodes=(Node("tf2_distance.py"),),
        spawn="start",
    ),
    Case(
        "tf_listener_drive",
        "turtlebot",
        "office",
        4.0,
        check_tf_listener,
        nodes=(Node("tf_listener_drive.py"),),
        spawn="start",
    ),
    Case(
        "shutdown_hook",
        "crowbot",
        "wall_approach",
        3.0,
        check_shutdown_hook,
        nodes=(Node("cmd_monitor.py"), Node("shutdown_stop.py")),
    ),
    Case(
        "slow_neighbour",
        "crowbot",
        "wall_approach",
        3.0,
        check_slow_neighbour,
        nodes=(Node("shutdown_stop.py"), Node("live_plot.py")),
    ),
    Case(
        "wait_for_scan",
        "turtlebot",
        "office",
        3.0,
        check_wait_for_scan,
        nodes=(Node("wait_for_scan.py"),),
        spawn="start",
    ),
    Case(
        "crowbot_pid",
        "crowbot",
        "wall_approach",
        9.0,
        check_crowbot_pid,
        nodes=(Node("crowbot_pid.py"),),
    ),
    Case(
        "crowbot_light",
        "crowbot",
        "light_arena",
        6.0,
        check_crowbot_light,
        nodes=(Node("crowbot_light.py"),),
        spawn="centre",
    ),
    Case(
        "tb3_obstacle_stop",
        "turtlebot3",
        "office",
        6.0,
        check_tb3_obstacle_stop,
        nodes=(Node("tb3_obstacle_stop.py"),),
        initial_pose=(2.6, 2.75, math.pi / 2),
    ),
    Case(
        "tb3_closest_obstacle",
        "turtlebot3",
        "office",
        4.0,
        check_tb3_closest,
        nodes=(Node("tb3_closest_obstacle.py"),),
        initial_pose=(3.0, 2.9, 0.0),
    ),
    Case(
        "debug_topic",
        "crowbot",
        "wall_approach",
        6.0,
        check_debug_topic,
        nodes=(Node("debug_topic.py"),),
    ),
    Case(
        "launch_file",
        "crowbot",
        "wall_approach",
        6.0,
        check_launch,
        launch="approach.launch",
    ),
    Case(
        "launch_file_args",
        "crowbot",
        "wall_approach",
        6.0,
        check_launch_with_args,
        launch="approach.launch",
        launch_args=("stop_distance:=0.45",),
        clocks=(Clock.LOCKSTEP,),  # the launch file's realtime run is launch_file's
    ),
    Case(
        "waypoints_csv",
        "turtlebot",
        "office",
        5.5,
        check_waypoints,
        nodes=(Node("waypoint_driver.py"),),
        spawn="start",
        files=("segments.csv",),
    ),
    Case(
        "yaml_config",
        "crowbot",
        "wall_approach",
        6.0,
        check_yaml_config,
        nodes=(Node("yaml_config_approach.py"),),
        files=("approach.yaml",),
    ),
    Case(
        "roslib_open_loop",
        "ir_scout",
        "wall_approach",
        4.0,
        check_roslib_open_loop,
        nodes=(Node("roslib_open_loop.py"),),
    ),
    Case(
        "ir_scout_commands",
        "ir_scout",
        "wall_approach",
        4.0,
        check_ir_scout_commands,
        nodes=(Node("ir_scout_commands.py"),),
    ),
    Case(
        "reactive_callback",
        "crowbot",
        "wall_approach",
        6.0,
        check_reactive,
        nodes=(Node("reactive_callback.py"),),
    ),
)


# The fast set (-m "not slow") runs a quick lockstep sample; each other case takes seconds.
FAST_CASES = ("class_approach", "params_default")


def _params():
    # Every lockstep run first, then the realtime ones (which take their duration in wall time).
    for clock in (Clock.LOCKSTEP, Clock.REALTIME):
        for case in CASES:
            if clock not in case.clocks:
                continue
            needs = case.needs + (case.realtime_needs if clock is Clock.REALTIME else ())
            marks = []
            if clock is Clock.REALTIME or case.id not in FAST_CASES:
                marks.append(pytest.mark.slow)
            if needs:
                marks.append(pytest.mark.xfail(reason="needs " + ", ".join(needs), strict=True))
            yield pytest.param(case, clock, id=f"{case.id}-{clock.value}", marks=marks)


@pytest.fixture(scope="module")
def realtime_runs(request, launcher, tmp_path_factory):
    """A realtime run takes its duration in wall time, mostly waiting: the selected ones start
    together at the first realtime test, a few at a time, and each test waits for its own."""
    cases = [
        item.callspec.params["case"]
        for item in request.session.items
        if getattr(item, "originalname", None) == "test_course_script_runs_unchanged"
        and item.callspec.params["clock"] is Clock.REALTIME
    ]
    pool, futures = start_realtime_runs(
        cases,
        launcher,
        lambda case_id: tmp_path_factory.mktemp(case_id) / "run",
        REALTIME_RUNS_AT_ONCE,
    )
    yield futures
    pool.shutdown(wait=True, cancel_futures=True)


@pytest.mark.parametrize(("case", "clock"), list(_params()))
def test_course_script_runs_unchanged(
    case: Case, clock: Clock, request, launcher, tmp_path
) -> None:
    if clock is Clock.REALTIME:
        outcome = request.getfixturevalue("realtime_runs")[case.id].result()
    else:
        outcome = run_case(case, clock, launcher, tmp_path / "run")
    assert outcome.state == "finished", outcome.describe()
    # A run ends at its duration, or earlier when every script has ended.
    assert outcome.reason in FINISHED, outcome.describe()
    for node, text in outcome.logs.items():
        assert "Traceback" not in text, f"node {node} raised: {outcome.describe()}"
    case.check(outcome)


# Course scripts that cannot run here, each with the sentence it must get instead of a bare
# error: the file's line, what is missing and what to use.
REFUSED = (
    (
        "add_two_ints_client.py",
        "ModuleNotFoundError at line 6",
        r"rospy_tutorials is not available in RoboDojo: .*use std_srvs",
    ),
    (
        "rate_before_init.py",
        "ROSInitException at line 7",
        r"rospy\.Rate\(\) needs a node: call rospy\.init_node",
    ),
)


@pytest.mark.parametrize(
    ("script", "raised", "sentence"), REFUSED, ids=[script for script, _, _ in REFUSED]
)
def test_a_script_that_cannot_run_gets_a_sentence(
    script: str, raised: str, sentence: str, launcher, tmp_path
) -> None:
    outcome = run_scripts(
        launcher,
        tmp_path / "run",
        robot="crowbot",
        world="wall_approach",
        nodes=(Node(script),),
        clock=Clock.LOCKSTEP,
        duration_s=2.0,
    )
    node = script.removesuffix(".py")
    assert outcome.state == "failed"
    assert outcome.reason == f"failed: node {node} raised {raised}", outcome.describe()
    log = outcome.log(node)
    assert re.search(sentence, log), log
    assert f'File "{script}", line' in log


def test_the_corpus_is_large_enough_and_every_script_is_used() -> None:
    scripts = {path.name for path in SCRIPTS.glob("*.py")}
    used = {node.file for case in CASES for node in case.nodes} | {s for s, _, _ in REFUSED}
    assert len(scripts) >= 25
    launched = {"launch_driver.py", "range_monitor.py"}  # named by approach.launch
    assert scripts == used | launched, scripts ^ (used | launched)
    for path in SCRIPTS.glob("*.py"):
        comment = path.read_text().splitlines()[1]
        assert comment.startswith("# Course pattern: "), path.name
