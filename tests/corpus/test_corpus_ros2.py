"""ROS 2 course nodes run unchanged (issue 13): each script in tests/corpus/scripts_ros2/ is
written the way ROS 2 course material writes it (the official tutorials, The Construct,
Articulated Robotics, the TurtleBot3 examples, Nav2's simple commander), run through the real
run engine and sandbox (server.runs.Run with the real launcher, or `robodojo run --launch` for
the Python launch file) on both clocks, and judged on behaviour by its check in
tests/corpus/checks_ros2.py. The recording of every run must be a ROS 2 one (profile "ros2",
ros2msg schemas, CDR messages), and the checks read it with mcap-ros2-support. A case whose
feature has not landed is a strict xfail naming it.
"""

from __future__ import annotations

import math
import re

import pytest

from sandbox.protocol import Clock
from server.runs.spec import RunSpecError
from tests.corpus import checks_ros2 as checks
from tests.corpus.harness import (
    SCRIPTS,
    SCRIPTS_ROS2,
    Case,
    Node,
    run_case,
    run_scripts,
    start_realtime_runs,
)

# Realtime runs wait on the wall clock most of the time; this many share the machine at once.
REALTIME_RUNS_AT_ONCE = 3
FINISHED = ("finished: duration reached", "finished: every node ended")
CORRIDOR_FACING_NORTH = (2.6, 3.1, math.pi / 2)  # [m, m, rad] 0.6 m from the corridor's wall
LANE_FOLLOWING = (2.6, 2.95, 0.0)  # [m, m, rad] 0.45 m left of the corridor's south wall


def ros2_case(case_id: str, robot: str, world: str, duration_s: float, check, **kwargs) -> Case:
    return Case(case_id, robot, world, duration_s, check, scripts=SCRIPTS_ROS2, **kwargs)


CASES = (
    ros2_case(
        "talker_listener",
        "crowbot",
        "wall_approach",
        3.0,
        checks.check_talker_listener,
        nodes=(Node("minimal_subscriber.py"), Node("minimal_publisher.py")),
    ),
    ros2_case(
        "lambda_approach",
        "crowbot",
        "wall_approach",
        6.0,
        checks.check_lambda_approach,
        nodes=(Node("lambda_approach.py"),),
    ),
    ros2_case(
        "spin_once_loop",
        "crowbot",
        "wall_approach",
        8.0,
        checks.check_spin_once_loop,
        nodes=(Node("spin_once_loop.py"),),
    ),
    ros2_case(
        "services",
        "crowbot",
        "wall_approach",
        2.0,
        checks.check_services,
        nodes=(Node("add_two_ints_server.py"), Node("add_two_ints_client.py", args=("41", "1"))),
    ),
    ros2_case(
        "params_default",
        "crowbot",
        "wall_approach",
        3.0,
        checks.check_params_default,
        nodes=(Node("param_driver.py"),),
    ),
    ros2_case(
        "params_ros_args",
        "crowbot",
        "wall_approach",
        3.5,
        checks.check_params_ros_args,
        nodes=(
            Node(
                "param_driver.py",
                args=(
                    "--ros-args",
                    "-p",
                    "speed:=0.1",
                    "-p",
                    "stop_distance:=0.45",
                    "-p",
                    "robot_name:=crowbot_7",
                ),
            ),
        ),
    ),
    ros2_case(
        "params_set",
        "crowbot",
        "wall_approach",
        3.0,
        checks.check_params_set,
        nodes=(Node("param_driver.py", params={"speed": 0.1, "robot_name": "crowbot_7"}),),
        clocks=(Clock.LOCKSTEP,),  # the parameters' realtime run is params_ros_args
    ),
    ros2_case(
        "param_callback",
        "crowbot",
        "wall_approach",
        2.5,
        checks.check_param_callback,
        nodes=(Node("param_callback.py"),),
    ),
    ros2_case(
        "qos_mismatch",
        "crowbot",
        "wall_approach",
        3.0,
        checks.check_qos_mismatch,
        nodes=(Node("sensor_relay.py"), Node("qos_mismatch_listener.py")),
    ),
    ros2_case(
        "latched",
        "crowbot",
        "wall_approach",
        2.0,
        checks.check_latched,
        nodes=(Node("latched_publisher.py"), Node("late_subscriber.py")),
    ),
    ros2_case(
        "map_listener",
        "turtlebot3",
        "office",
        2.0,
        checks.check_map_listener,
        nodes=(Node("map_listener.py"),),
        spawn="start",
        builtin_nodes=("map_server",),
    ),
    ros2_case(
        "fibonacci_action",
        "crowbot",
        "wall_approach",
        4.0,
        checks.check_fibonacci_action,
        nodes=(Node("fibonacci_action_server.py"), Node("fibonacci_action_client.py")),
    ),
    ros2_case(
        "sync_call_timer",
        "crowbot",
        "wall_approach",
        3.0,
        checks.check_sync_call_timer,
        nodes=(Node("add_two_ints_server.py"), Node("sync_call_timer.py")),
    ),
    ros2_case(
        "rate_in_thread",
        "turtlebot",
        "office",
        7.5,
        checks.check_rate_in_thread,
        nodes=(Node("rate_in_thread.py"),),
        spawn="start",
    ),
    ros2_case(
        "tf2_odom_distance",
        "turtlebot3",
        "office",
        5.0,
        checks.check_tf2_odom_distance,
        nodes=(Node("tf2_odom_distance.py"),),
        spawn="start",
    ),
    ros2_case(
        "tf2_map_turn",
        "turtlebot",
        "office",
        5.5,
        checks.check_tf2_map_turn,
        nodes=(Node("tf2_map_turn.py"),),
        spawn="start",
    ),
    ros2_case(
        "go_to_goal",
        "turtlebot3",
        "office",
        8.0,
        checks.check_go_to_goal,
        nodes=(Node("go_to_goal.py"),),
        spawn="start",
    ),
    ros2_case(
        "tb3_obstacle_avoider",
        "turtlebot3",
        "office",
        6.0,
        checks.check_tb3_obstacle_avoider,
        nodes=(Node("tb3_obstacle_avoider.py"),),
        initial_pose=CORRIDOR_FACING_NORTH,
    ),
    ros2_case(
        "tb3_stamped_stop",
        "turtlebot3",
        "office",
        6.0,
        checks.check_tb3_stamped_stop,
        nodes=(Node("tb3_stamped_stop.py"),),
        initial_pose=(2.6, 2.75, math.pi / 2),
    ),
    ros2_case(
        "tb3_wall_follower",
        "turtlebot3",
        "office",
        6.0,
        checks.check_wall_follower,
        nodes=(Node("tb3_wall_follower.py"),),
        initial_pose=LANE_FOLLOWING,
    ),
    ros2_case(
        "crowbot_pid",
        "crowbot",
        "wall_approach",
        9.0,
        checks.check_crowbot_pid,
        nodes=(Node("crowbot_pid.py"),),
    ),
    ros2_case(
        "ir_scout_node",
        "ir_scout",
        "wall_approach",
        4.5,
        checks.check_ir_scout,
        nodes=(Node("ir_scout_node.py"),),
    ),
    ros2_case(
        "crop_rover_node",
        "crop_rover",
        "crop_rows",
        7.0,
        checks.check_crop_rover,
        nodes=(Node("crop_rover_node.py"),),
        spawn="start",
    ),
    ros2_case(
        "throttled_logger",
        "crowbot",
        "wall_approach",
        3.5,
        checks.check_throttled_logger,
        nodes=(Node("throttled_logger.py"),),
    ),
    ros2_case(
        "shutdown_from_callback",
        "crowbot",
        "wall_approach",
        7.0,
        checks.check_shutdown_from_callback,
        nodes=(Node("shutdown_from_callback.py"),),
    ),
    ros2_case(
        "clean_shutdown_main",
        "crowbot",
        "wall_approach",
        2.5,
        checks.check_clean_shutdown,
        nodes=(Node("clean_shutdown_main.py"),),
    ),
    ros2_case(
        "two_nodes_one_file",
        "crowbot",
        "wall_approach",
        6.0,
        checks.check_two_nodes_one_file,
        nodes=(Node("two_nodes_one_file.py"),),
    ),
    ros2_case(
        "nav2_goto_pose",
        "turtlebot3",
        "office",
        25.0,
        checks.check_nav2_goto_pose,
        nodes=(Node("nav2_goto_pose.py"),),
        spawn="start",
        builtin_nodes=("map_server", "localization", "nav2"),
    ),
    ros2_case(
        "launch_file",
        "crowbot",
        "wall_approach",
        6.0,
        checks.check_launch,
        launch="launch/approach.launch.py",
    ),
    ros2_case(
        "ament_package_launch",
        "turtlebot3",
        "office",
        9.0,
        checks.check_ament_package_launch,
        launch="patrol_pkg/launch/patrol.launch.py",
        launch_args=("leg_length:=0.3",),  # a launch argument from the command line
        spawn="corridor",
    ),
)


# The fast set (-m "not slow") runs a quick lockstep sample; each other case takes seconds.
FAST_CASES = ("params_set", "clean_shutdown_main")


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
def realtime_runs_ros2(request, launcher, tmp_path_factory):
    """The selected realtime runs start together at the first realtime test, a few at a time,
    and each test waits for its own."""
    cases = [
        item.callspec.params["case"]
        for item in request.session.items
        if getattr(item, "originalname", None) == "test_ros2_course_node_runs_unchanged"
        and item.callspec.params["clock"] is Clock.REALTIME
    ]
    pool, futures = start_realtime_runs(
        cases,
        launcher,
        lambda case_id: tmp_path_factory.mktemp(f"ros2_{case_id}") / "run",
        REALTIME_RUNS_AT_ONCE,
    )
    yield futures
    pool.shutdown(wait=True, cancel_futures=True)


@pytest.mark.parametrize(("case", "clock"), list(_params()))
def test_ros2_course_node_runs_unchanged(
    case: Case, clock: Clock, request, launcher, tmp_path
) -> None:
    if clock is Clock.REALTIME:
        outcome = request.getfixturevalue("realtime_runs_ros2")[case.id].result()
    else:
        outcome = run_case(case, clock, launcher, tmp_path / "run")
    assert outcome.state == "finished", outcome.describe()
    # A run ends at its duration, or earlier when every script has ended.
    assert outcome.reason in FINISHED, outcome.describe()
    for node, text in outcome.logs.items():
        assert "Traceback" not in text, f"node {node} raised: {outcome.describe()}"
    # What `ros2 bag record` writes: the ros2 profile, ros2msg schemas and CDR messages.
    profile, encodings = outcome.recording_format
    assert (profile, encodings) == ("ros2", {("ros2msg", "cdr")}), (profile, encodings)
    case.check(outcome)


# ROS 2 code that cannot run here, each with the sentence it must get instead of a bare error.
REFUSED = (
    (
        "turtlesim_chaser.py",
        "ModuleNotFoundError at line 6",
        r"turtlesim is not available in RoboDojo",
    ),
)


@pytest.mark.parametrize(
    ("script", "raised", "sentence"), REFUSED, ids=[script for script, _, _ in REFUSED]
)
def test_a_ros2_node_that_cannot_run_gets_a_sentence(
    script: str, raised: str, sentence: str, launcher, tmp_path
) -> None:
    outcome = run_scripts(
        launcher,
        tmp_path / "run",
        robot="turtlebot3",
        world="office",
        nodes=(Node(script),),
        clock=Clock.LOCKSTEP,
        duration_s=2.0,
        scripts=SCRIPTS_ROS2,
    )
    node = script.removesuffix(".py")
    assert outcome.state == "failed"
    assert outcome.reason == f"failed: node {node} raised {raised}", outcome.describe()
    log = outcome.log(node)
    assert re.search(sentence, log), log
    assert f'File "{script}", line' in log


def test_a_run_is_ros1_or_ros2_never_both(launcher, tmp_path) -> None:
    # The ROS 2 talker beside the ROS 1 listener: refused before anything starts, naming both.
    mixed = (Node("minimal_publisher.py"), Node("../scripts/listener.py", name="listener"))
    with pytest.raises(RunSpecError) as refused:
        run_scripts(
            launcher,
            tmp_path / "run",
            robot="crowbot",
            world="wall_approach",
            nodes=mixed,
            clock=Clock.LOCKSTEP,
            duration_s=1.0,
            scripts=SCRIPTS_ROS2,
        )
    assert str(refused.value) == (
        "node `minimal_publisher` uses rclpy (ROS 2) and node `listener` uses rospy (ROS 1); "
        "a run is one or the other"
    )
    assert (SCRIPTS / "listener.py").is_file()


def test_the_ros2_corpus_is_large_enough_and_every_script_is_used() -> None:
    scripts = {path.name for path in SCRIPTS_ROS2.glob("*.py")}
    used = {node.file for case in CASES for node in case.nodes} | {s for s, _, _ in REFUSED}
    launched = {"launch_driver.py", "range_monitor.py"}  # named by launch/approach.launch.py
    assert len(scripts) >= 24
    assert scripts == used | launched, scripts ^ (used | launched)
    for path in SCRIPTS_ROS2.rglob("*.py"):
        if path.name == "__init__.py":
            continue
        lines = path.read_text().splitlines()
        comment = lines[1] if lines[0].startswith("#!") else lines[0]
        assert comment.startswith("# Course pattern: "), path.name
