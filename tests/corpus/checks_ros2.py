"""What each ROS 2 corpus script must do, judged from its run's output: where the robot went
(the true pose from the recording's /tf), which messages flowed (the recording, decoded from
its own ros2msg schemas; the run's graph), what the logs say and which files came back. One
check function per case of test_corpus_ros2.py. The geometry is checks.py's; the office's
lab spawn "start" is (2.0, 1.3) facing +y, and its corridor's north wall is at y = 3.7.
"""

from __future__ import annotations

import csv
import io
import math
import re

import pytest

from sandbox.protocol import Clock
from tests.corpus.checks import (
    LOCKSTEP_SHARE,
    REALTIME_SHARE,
    angle_between,
    assert_log,
    assert_still_after,
    at_least,
    sensor_distance,
    travelled,
)
from tests.corpus.harness import Outcome

IR_SCOUT_SENSOR_AHEAD_M = 0.045  # [m] the IR ranger's servo horn ahead of the robot's centre
BOARD_X_M = 1.40  # [m] wall_approach: the board's face
CORRIDOR_NORTH_WALL_Y_M = 3.7  # [m] office
LAB_START = (2.0, 1.3, math.pi / 2)  # [m, m, rad] office spawn "start"
FIBONACCI_7 = [0, 1, 1, 2, 3, 5, 8]  # order 6: the seed pair and five more


def logged(outcome: Outcome, node: str, pattern: str) -> list[str]:
    """Every match of `pattern` (its first group, or the whole match) in `node`'s log."""
    return re.findall(pattern, outcome.log(node))


def publishers(outcome: Outcome, topic: str) -> list[str]:
    entry = outcome.graph.get(topic)
    assert entry is not None, f"no topic {topic} in the run's graph: {sorted(outcome.graph)}"
    return entry["publishers"]


def share(outcome: Outcome) -> float:
    return REALTIME_SHARE if outcome.clock is Clock.REALTIME else LOCKSTEP_SHARE


# ------------------------------------------------------------------------------------ checks
def check_talker_listener(outcome: Outcome) -> None:
    heard = logged(outcome, "minimal_subscriber", r'I heard: "Hello ROS 2: (\d+)"')
    heard = [int(n) for n in heard]
    assert len(heard) >= at_least(outcome, 10, 3.0), outcome.describe()
    # Reliable, depth 10, a subscriber that keeps up: every message, in order.
    assert heard == list(range(heard[0], heard[0] + len(heard))), heard
    assert heard[0] <= 2, heard[:3]
    sent = logged(outcome, "minimal_publisher", r'Publishing: "Hello ROS 2: (\d+)"')
    assert len(sent) >= len(heard)
    chatter = [message.data for _, message in outcome.messages("chatter")]
    assert chatter[0] == "Hello ROS 2: 0" and len(chatter) >= at_least(outcome, 10, 3.0)
    assert len(publishers(outcome, "chatter")) == 1
    assert len(outcome.graph["chatter"]["subscribers"]) == 1


def check_lambda_approach(outcome: Outcome) -> None:
    assert sensor_distance(outcome.end.x) == pytest.approx(0.35, abs=0.03)
    assert outcome.metrics["run"]["collisions"] == 0
    control = outcome.messages("Control")
    assert len(control) >= at_least(outcome, 20, 5.0), len(control)
    assert control[0][1].linear.x == pytest.approx(0.1)  # 0.6 m away: full speed first


def check_spin_once_loop(outcome: Outcome) -> None:
    close_cm = int(assert_log(outcome, "spin_once_loop", r"close enough: (\d+) cm").group(1))
    assert 25 <= close_cm <= 30, close_cm
    assert outcome.reason == "finished: every node ended", outcome.reason
    assert sensor_distance(outcome.end.x) == pytest.approx(0.30, abs=0.03)
    # Its last command was a zero Twist: the robot stands where the loop ended.
    assert outcome.messages("Control")[-1][1].linear.x == 0.0


def check_services(outcome: Outcome) -> None:
    assert_log(outcome, "add_two_ints_client", r"Result of add_two_ints: for 41 \+ 1 = 42")
    assert_log(outcome, "add_two_ints_client", r"and again: 40")
    requests = logged(outcome, "add_two_ints_server", r"Incoming request a: (-?\d+) b: (-?\d+)")
    assert requests == [("41", "1"), ("42", "-2")], requests
    # The calls are in the recording (as rosbag2 keeps a service's traffic).
    service_topics = [topic for topic in outcome.recording if "add_two_ints" in topic]
    assert service_topics, sorted(outcome.recording)


def check_params_default(outcome: Outcome) -> None:
    assert_log(outcome, "param_driver", r"unnamed robot: speed 0\.05 m/s, stop at 0\.25 m")
    assert outcome.travelled_between(0.0, 3.0) == travelled(outcome, 0.15, 0.03)


def check_params_ros_args(outcome: Outcome) -> None:
    # --ros-args -p speed:=0.1 -p stop_distance:=0.45 -p robot_name:=crowbot_7
    assert_log(outcome, "param_driver", r"crowbot_7: speed 0\.10 m/s, stop at 0\.45 m")
    assert sensor_distance(outcome.end.x) == pytest.approx(0.45, abs=0.03)
    assert_still_after(outcome, outcome.end.t - 1.0)


def check_params_set(outcome: Outcome) -> None:
    assert_log(outcome, "param_driver", r"crowbot_7: speed 0\.10 m/s, stop at 0\.25 m")
    assert outcome.travelled_between(0.0, 3.0) == travelled(outcome, 0.30, 0.04)


def check_param_callback(outcome: Outcome) -> None:
    node = "param_callback"
    assert_log(outcome, node, r"rejected speed -1\.0")
    assert_log(outcome, node, r"setting -1\.0: successful=False")
    assert_log(outcome, node, r"speed is now 0\.10 m/s")
    assert_log(outcome, node, r"setting 0\.1: successful=True")
    assert_log(outcome, node, r"parameter now 0\.1\b")
    # 0.05 m/s for the first second, then 0.1 m/s.
    assert outcome.travelled_between(0.0, 1.0) == travelled(outcome, 0.05, 0.02)
    assert outcome.travelled_between(1.2, 2.2) == travelled(outcome, 0.10, 0.025)


def check_qos_mismatch(outcome: Outcome) -> None:
    node = "qos_mismatch_listener"
    counts = logged(outcome, node, r"reliable: (\d+) messages, best effort: (\d+)")
    assert len(counts) >= 2, outcome.describe()
    reliable, best_effort = (int(value) for value in counts[-1])
    assert reliable == 0, counts  # a RELIABLE request is not met by a BEST_EFFORT offer
    assert best_effort >= at_least(outcome, 20, 1.5), counts
    # rclpy's warning on the subscriber's side names the policy.
    assert_log(
        outcome,
        node,
        r"New publisher discovered on topic '/range_m', offering incompatible QoS\..*"
        r"Last incompatible policy: RELIABILITY",
    )
    relayed = outcome.messages("range_m")
    assert len(relayed) >= at_least(outcome, 20, 2.5), len(relayed)
    assert relayed[0][1].data == pytest.approx(0.60, abs=0.02)


def check_latched(outcome: Outcome) -> None:
    assert_log(outcome, "latched_publisher", r"mission published once")
    log = outcome.log("late_subscriber")
    assert "joining now" in log, outcome.describe()
    after_join = log[log.index("joining now") :]
    assert re.search(r"transient local got: inspect the north corridor", after_join), log
    assert "volatile got" not in log, log  # VOLATILE: nothing published after it joined
    mission = outcome.messages("mission")
    assert [message.data for _, message in mission] == ["inspect the north corridor"]


def check_map_listener(outcome: Outcome) -> None:
    # map_server offers `map` TRANSIENT_LOCAL and RELIABLE, as Nav2's does: a match, no warning.
    assert "incompatible QoS" not in outcome.log("map_listener"), outcome.log("map_listener")
    match = assert_log(
        outcome,
        "map_listener",
        r"map (\d+)x(\d+) at (\d\.\d+) m/cell, frame map, (\d+) occupied cells",
    )
    recorded = outcome.messages("map")
    assert recorded, sorted(outcome.recording)
    grid = recorded[-1][1]
    assert (int(match.group(1)), int(match.group(2))) == (grid.info.width, grid.info.height)
    assert float(match.group(3)) == pytest.approx(grid.info.resolution, abs=0.0005)
    occupied = sum(1 for cell in grid.data if cell > 50)
    assert int(match.group(4)) == occupied > 100


def check_fibonacci_action(outcome: Outcome) -> None:
    assert_log(outcome, "fibonacci_action_server", r"Executing goal\.\.\.")
    assert_log(outcome, "fibonacci_action_client", r"Goal accepted :\)")
    feedback = logged(outcome, "fibonacci_action_client", r"Received feedback: (\[[\d, ]+\])")
    expected = [str(FIBONACCI_7[: n + 1]) for n in range(2, len(FIBONACCI_7))]
    assert feedback == expected, feedback
    assert_log(outcome, "fibonacci_action_client", re.escape(f"Result: {FIBONACCI_7}"))
    # Feedback on the action's topic, 0.5 s apart (the server sleeps between steps).
    messages = outcome.messages("fibonacci/_action/feedback")
    assert len(messages) == 5, sorted(outcome.recording)
    assert list(messages[-1][1].feedback.partial_sequence) == FIBONACCI_7
    spread = messages[-1][0] - messages[0][0]
    high = 3.0 if outcome.clock is Clock.REALTIME else 2.1
    assert 1.9 <= spread <= high, spread


def check_sync_call_timer(outcome: Outcome) -> None:
    totals = [int(n) for n in logged(outcome, "sync_call_timer", r"call \d+: total is (\d+)")]
    assert totals == [3 * k for k in range(1, 9)], totals
    assert_log(outcome, "sync_call_timer", r"done: 8 calls")
    served = logged(outcome, "add_two_ints_server", r"Incoming request a: (\d+) b: 3")
    assert [int(a) for a in served] == [3 * k for k in range(8)], served


def check_rate_in_thread(outcome: Outcome) -> None:
    assert_log(outcome, "rate_in_thread", r"step 2: v=0\.15 w=0\.00")
    assert_log(outcome, "rate_in_thread", r"L done")
    assert outcome.reason == "finished: every node ended", outcome.reason
    # 0.3 m ahead, a quarter turn left, 0.3 m ahead: open loop, so a realtime run on a loaded
    # machine may cut or stretch a leg by a wake-up or two.
    realtime = outcome.clock is Clock.REALTIME
    start, end = outcome.start, outcome.end
    assert angle_between(end.yaw, start.yaw) == pytest.approx(
        math.pi / 2, abs=0.35 if realtime else 0.15
    )
    heading = start.yaw + math.pi / 2
    expected_x = start.x + 0.3 * math.cos(start.yaw) + 0.3 * math.cos(heading)
    expected_y = start.y + 0.3 * math.sin(start.yaw) + 0.3 * math.sin(heading)
    miss = math.hypot(end.x - expected_x, end.y - expected_y)
    assert miss < (0.2 if realtime else 0.1), (end, expected_x, expected_y)


def check_tf2_odom_distance(outcome: Outcome) -> None:
    assert_log(outcome, "tf2_odom_distance", r"travelled 0\.3\d m")
    assert outcome.travelled_between(0.0, outcome.end.t) == travelled(outcome, 0.3, 0.05)
    assert_still_after(outcome, outcome.end.t - 1.0)


def check_tf2_map_turn(outcome: Outcome) -> None:
    assert_log(outcome, "tf2_map_turn", r"start in map: x=2\.00 y=1\.30 yaw=1\.57")
    assert angle_between(outcome.end.yaw, outcome.start.yaw) == pytest.approx(
        math.pi / 2, abs=math.radians(6)
    )
    assert outcome.travelled_between(0.0, outcome.end.t) < 0.05


def check_go_to_goal(outcome: Outcome) -> None:
    assert_log(outcome, "go_to_goal", r"goal reached: x=0\.[56]\d y=0\.[23]\d")
    # The goal (0.6, 0.3) in odom, which starts at the lab spawn facing +y: (1.7, 1.9) on the map.
    x0, y0, yaw0 = LAB_START
    goal_x = x0 + 0.6 * math.cos(yaw0) - 0.3 * math.sin(yaw0)
    goal_y = y0 + 0.6 * math.sin(yaw0) + 0.3 * math.cos(yaw0)
    end = outcome.end
    assert math.hypot(end.x - goal_x, end.y - goal_y) < 0.1, (end, goal_x, goal_y)
    assert outcome.metrics["run"]["collisions"] == 0


def check_tb3_obstacle_avoider(outcome: Outcome) -> None:
    assert_log(outcome, "tb3_obstacle_avoider", r"obstacle at 0\.4\d m, turning")
    assert_log(outcome, "tb3_obstacle_avoider", r"path clear, driving")
    assert outcome.metrics["run"]["collisions"] == 0
    assert outcome.turned() > 0.3, outcome.turned()  # it turns left
    assert all(pose.y < CORRIDOR_NORTH_WALL_Y_M - 0.1 for pose in outcome.poses)
    assert outcome.travelled_between(0.0, outcome.end.t) >= 0.3
    commands = outcome.messages("cmd_vel")
    assert len(commands) >= at_least(outcome, 10, 5.0)


def check_tb3_stamped_stop(outcome: Outcome) -> None:
    # A 10 Hz timer acting on the last 5 Hz scan at 0.15 m/s: the robot stops 4-6 cm past the
    # 0.35 m threshold (0.29 m in lockstep); a realtime run's late wake-ups may add a few more.
    gap_m = CORRIDOR_NORTH_WALL_Y_M - outcome.end.y
    closest_m = 0.23 if outcome.clock is Clock.REALTIME else 0.27
    assert closest_m <= gap_m <= 0.35, gap_m
    assert_still_after(outcome, outcome.end.t - 1.0, within_m=0.04)
    assert_log(outcome, "tb3_stamped_stop", r"Stop! obstacle at 0\.3\d m")
    # The node's commands, then the run's own zero at its end, in the type the node used.
    *commands, last = [message for _, message in outcome.messages("cmd_vel")]
    assert commands and all(message.header.frame_id == "base_link" for message in commands)
    assert last.twist.linear.x == last.twist.angular.z == 0.0
    stamps = [message.header.stamp.sec + message.header.stamp.nanosec / 1e9 for message in commands]
    assert stamps == sorted(stamps) and stamps[-1] - stamps[0] >= 4.0, stamps[:3]
    assert commands[0].twist.linear.x == pytest.approx(0.15)


def check_wall_follower(outcome: Outcome) -> None:
    assert outcome.end.x - outcome.start.x >= 0.5, outcome.end
    for pose in outcome.poses:
        assert 2.75 <= pose.y <= 3.25, pose  # kept off the south wall (y = 2.5)
    assert outcome.metrics["run"]["collisions"] == 0


def check_crowbot_pid(outcome: Outcome) -> None:
    assert sensor_distance(outcome.end.x) == pytest.approx(0.20, abs=0.03)
    assert outcome.metrics["run"]["collisions"] == 0
    saved = int(assert_log(outcome, "crowbot_pid", r"saved (\d+) samples").group(1))
    path = outcome.artifact("crowbot_pid", "pid_samples.csv")
    assert path.is_file(), outcome.describe()
    rows = list(csv.DictReader(io.StringIO(path.read_text())))
    assert len(rows) == saved >= at_least(outcome, 10, 8.0)
    assert float(rows[0]["error"]) == pytest.approx(0.40, abs=0.02)
    assert abs(float(rows[-1]["error"])) < 0.03
    times = [float(row["t"]) for row in rows]
    assert times == sorted(times)


def check_ir_scout(outcome: Outcome) -> None:
    match = assert_log(outcome, "ir_scout_node", r"obstacle at (0\.\d\d) m: stop")
    stop_range = float(match.group(1))
    assert 0.20 <= stop_range <= 0.25  # the log rounds the range to 2 decimals
    end_range = BOARD_X_M - IR_SCOUT_SENSOR_AHEAD_M - outcome.end.x
    assert end_range == pytest.approx(0.24, abs=0.03)
    assert_still_after(outcome, outcome.end.t - 0.8)
    words = [message.data for _, message in outcome.messages("motor_command")]
    assert words[0] == "forward" and words[-1] == "stop", words[:2] + words[-2:]
    angles = {message.data for _, message in outcome.messages("servo_angle")}
    assert angles == {90}


def check_crop_rover(outcome: Outcome) -> None:
    assert outcome.end.x - outcome.start.x >= 0.7, outcome.end
    for pose in outcome.poses:
        assert 1.0 <= pose.y <= 1.42, pose  # in its lane: rows at y = 0.8 and 1.6
    control = [message.data for _, message in outcome.messages("u")]
    assert len(control) >= at_least(outcome, 7, 6.0), len(control)
    assert all(-60.0 <= u <= 60.0 for u in control)
    assert_log(outcome, "crop_rover_node", r"row at 0\.\d\d m, u = -?\d+\.\d")
    assert outcome.metrics["run"]["collisions"] == 0


def check_throttled_logger(outcome: Outcome) -> None:
    readings = logged(outcome, "throttled_logger", r"distance \d+ cm \((\d+) readings\)")
    # At most one line a second over 3.5 s (the first at once), though Distance comes at 20 Hz.
    assert 3 <= len(readings) <= 4, readings
    counts = [int(n) for n in readings]
    assert counts[0] <= 2 and counts[-1] - counts[0] >= at_least(outcome, 20, 2.0), counts
    assert len(logged(outcome, "throttled_logger", r"first reading received")) == 1


def check_shutdown_from_callback(outcome: Outcome) -> None:
    reached = int(
        assert_log(outcome, "shutdown_from_callback", r"reached (\d+) cm, shutting down").group(1)
    )
    assert 25 <= reached <= 30, reached
    assert_log(outcome, "shutdown_from_callback", r"spin returned")
    assert outcome.reason == "finished: every node ended", outcome.reason
    assert sensor_distance(outcome.end.x) == pytest.approx(0.30, abs=0.03)


def check_clean_shutdown(outcome: Outcome) -> None:
    ticks = int(
        assert_log(outcome, "clean_shutdown_main", r"interrupted after (\d+) ticks").group(1)
    )
    assert at_least(outcome, 10, 2.5) <= ticks <= 26, ticks
    assert outcome.reason == "finished: duration reached"
    assert outcome.travelled_between(0.0, 2.5) == travelled(outcome, 0.18, 0.04)


def check_two_nodes_one_file(outcome: Outcome) -> None:
    assert sensor_distance(outcome.end.x) == pytest.approx(0.40, abs=0.03)
    ranges = [message.data for _, message in outcome.messages("range_m")]
    assert len(ranges) >= at_least(outcome, 20, 5.0), len(ranges)
    assert ranges[0] == pytest.approx(0.60, abs=0.02)
    control = outcome.messages("Control")
    assert len(control) >= share(outcome) * len(ranges) - 1, (len(control), len(ranges))


def check_nav2_goto_pose(outcome: Outcome) -> None:
    assert_log(outcome, "nav2_goto_pose", r"Goal succeeded!")
    assert logged(outcome, "nav2_goto_pose", r"Distance remaining: (\d+\.\d+) m")
    end = outcome.end
    # Nav2's goal checker stops within 0.25 m of the goal by the localization's estimate.
    assert math.hypot(end.x - 2.5, end.y - 2.0) < 0.3, end
    assert outcome.metrics["run"]["collisions"] == 0
    assert outcome.reason == "finished: every node ended"


def check_ament_package_launch(outcome: Outcome) -> None:
    # Parameters: speed from the YAML's /** section, turn_speed from its `patrol` section,
    # leg_length:=0.3 from the command line over the launch argument's default 0.4.
    assert_log(outcome, "patrol", r"patrol: legs of 0\.30 m at 0\.12 m/s, use_sim_time=True")
    assert_log(outcome, "patrol", r"leg out done at x=0\.3\d y=-?0\.0\d")
    assert_log(outcome, "patrol", r"turned around")
    assert_log(outcome, "patrol", r"leg back done")
    start, end = outcome.start, outcome.end
    assert math.hypot(end.x - start.x, end.y - start.y) < 0.1, (start, end)
    assert angle_between(end.yaw, start.yaw + math.pi) == pytest.approx(0.0, abs=0.15)
    farthest = max(pose.x for pose in outcome.poses) - start.x
    assert farthest == pytest.approx(0.30, abs=0.05)
    # The logger's wheel_odom is remapped to the robot's odom; it logs once a second.
    lines = logged(outcome, "odom_logger", r"tb3 odom: x=(-?\d\.\d\d) y=-?\d\.\d\d")
    assert len(lines) >= at_least(outcome, 1, 7.0), lines
    assert publishers(outcome, "cmd_vel") == ["patrol"]


def check_launch(outcome: Outcome) -> None:
    stop_distance_m = 0.30  # the launch argument's default
    assert_log(
        outcome,
        "driver",
        rf"crowbot_lab_3: speed 0\.10, stop at {stop_distance_m:.2f} m, kp 0\.80",
    )
    assert sensor_distance(outcome.end.x) == pytest.approx(stop_distance_m, abs=0.03)
    # namespace="monitor": the monitor's relative topic lands in it; the remappings bring both
    # nodes to the robot's Distance.
    assert_log(
        outcome, "range_monitor", r"namespace /monitor, publishing /monitor/too_close, threshold 40"
    )
    assert len(outcome.graph["Distance"]["subscribers"]) == 2, outcome.graph["Distance"]
    assert "cmd_vel" not in outcome.recording
    too_close = [message.data for _, message in outcome.messages("monitor/too_close")]
    assert too_close and not too_close[0], too_close[:3]
    # The monitor's threshold is 40 cm: it turns true once the robot is that close.
    assert too_close[-1] is (stop_distance_m < 0.40), too_close[-3:]
