"""What each corpus script must do, judged from its run's output: where the robot went (the
true pose from the recording), which messages flowed (recorded topics, the run's graph), what
the logs say and which figures and files came back. One check function per case of
test_corpus.py.

Geometry used by the checks (server/sim/worlds/*.toml):
- wall_approach: the board's face at x = 1.40 m; the CrowBot starts at x = 0.75 m facing it
  with its ultrasonic sensor 0.05 m ahead of its centre, so the sensor reads 1.35 - x [m].
- light_arena: the CrowBot at (1, 1) facing +x, the lamp 0.6 m to its left (+y).
- office: the lab spawn "start" at (2.0, 1.3) facing +y with 1.2 m free ahead; the corridor
  between y = 2.5 and y = 3.7, its south wall unbroken for 2.4 < x < 5.6 and its north wall
  for 1.8 < x < 5.0.
"""

from __future__ import annotations

import csv
import io
import itertools
import math
import re

import pytest

from sandbox.protocol import Clock
from server.runs.metrics import LATEST_WAKES_KEPT
from tests.corpus.harness import Outcome, png_size

BOARD_X_M = 1.40  # [m] wall_approach: the board's face
CROWBOT_SENSOR_AHEAD_M = 0.05  # [m] ultrasonic sensor ahead of the CrowBot's centre
FIGURE_PX = (2400, 1200)  # [px] the CrowBot paper's figures: 12 x 6 in at 200 dpi
STILL_M = 0.01  # [m] less than this between two poses: the robot stood still
LOCKSTEP_SHARE = 0.9  # of the periods a lockstep run must show (start-up and end cost one each)
REALTIME_SHARE = 0.6  # ... a realtime run must show (wake-ups come late on a loaded machine)
# [m] square_time_now's farthest from its start when its wakes come on time. A 0.3 m square's
# diagonal is 0.42 m; its turns fall short of 90 degrees (the wheels' acceleration limit), which
# opens it: 0.44 m in lockstep, 0.43-0.45 m in realtime on an idle machine (a move ends at the
# busy loop's next yield, sandbox/busy_loop.py).
SQUARE_FARTHEST_M = 0.5


def at_least(outcome: Outcome, rate_hz: float, seconds: float) -> int:
    """How many periodic messages a run must show at least. Lockstep: all but a few. Realtime:
    most of them (a rate loop keeps its schedule on the run's clock; a late wake-up on a loaded
    machine may cost a period)."""
    share = REALTIME_SHARE if outcome.clock is Clock.REALTIME else LOCKSTEP_SHARE
    return math.floor(share * rate_hz * seconds)


def travelled(outcome: Outcome, expected_m: float, lockstep_tolerance_m: float) -> object:
    """What a distance driven should compare equal to. Realtime: twice the tolerance, because a
    loaded machine's late start-up or wake-ups shift when the robot moves, as on a real one."""
    factor = 2.0 if outcome.clock is Clock.REALTIME else 1.0
    return pytest.approx(expected_m, abs=lockstep_tolerance_m * factor)


def drift_from_late_wakes(outcome: Outcome, node: str, topic: str) -> float:
    """How much farther [m] from its start a busy-looping open-loop script may have taken the
    robot because wakes came late (zero in lockstep, where wakes come on time): what the run's
    own lateness figures explain, not a guess.

    A `while rospy.Time.now() < end:` loop sees a move's end at the first wake past it, and its
    next command reaches the robot with the reply to that wake. So when a straight move ends,
    its command stays on for as long as the wake that saw the end came late, and for as long as
    the reply carrying the next command waited to be taken; a busy loop asks to be woken at once,
    so that wait is the lateness of the wake after. Each costs the move's speed times its length.
    The turn that follows starts that late but, timed from when the end was seen, stops on time:
    it falls short by its angular speed times the wait, and the rest of the path swings out about
    the corner by that angle times the corner's distance from the start.

    The wake that saw the end began with or after the reply before the change (the message before
    it on `topic`) and before the reply that changed it; the wake after, before the next reply.
    The run's latest wakes say how late each was (server/runs/metrics.py)."""
    latest = outcome.metrics["nodes"][node]["latest_wakes"]
    # A wake that is not among the latest was no later than the least late of them.
    unlisted_s = min(wake["late_s"] for wake in latest) if len(latest) >= LATEST_WAKES_KEPT else 0

    def lateness_s(from_s: float, to_s: float) -> float:
        """How late the wake that began in [from_s, to_s) came, at most."""
        in_window = [wake["late_s"] for wake in latest if from_s <= wake["at_s"] < to_s]
        return max(in_window, default=unlisted_s)

    messages = outcome.messages(topic)
    times_s = [time_s for time_s, _ in messages]
    drift_m = 0.0
    for index, ((before_s, ended), (changed_s, command)) in enumerate(
        itertools.pairwise(messages), start=1
    ):
        if ended.linear.x == 0.0 or command.linear.x == ended.linear.x:
            continue
        after_s = next((t for t in times_s[index:] if t > changed_s), math.inf)
        seen_late_s = lateness_s(before_s, changed_s)
        reply_waited_s = lateness_s(changed_s, after_s)
        corner = outcome.pose_at(changed_s)
        corner_m = math.hypot(corner.x - outcome.start.x, corner.y - outcome.start.y)
        drift_m += abs(ended.linear.x) * (seen_late_s + reply_waited_s)
        drift_m += abs(command.angular.z) * reply_waited_s * corner_m
    return drift_m


def sensor_distance(x_m: float) -> float:
    """The CrowBot's ultrasonic range [m] to the board from its centre's x in wall_approach."""
    return BOARD_X_M - CROWBOT_SENSOR_AHEAD_M - x_m


def angle_between(a: float, b: float) -> float:
    return math.atan2(math.sin(a - b), math.cos(a - b))


def assert_still_after(outcome: Outcome, time_s: float, within_m: float = STILL_M) -> None:
    moved = outcome.travelled_between(time_s, outcome.end.t)
    assert moved < within_m, f"the robot still moved {moved:.3f} m after t={time_s} s"


def assert_log(outcome: Outcome, node: str, pattern: str) -> re.Match:
    match = re.search(pattern, outcome.log(node))
    assert match, f"node {node}'s log has no line matching {pattern!r}: {outcome.describe()}"
    return match


def assert_figures(outcome: Outcome, node: str, *names: str) -> None:
    for name in names:
        path = outcome.artifact(node, name)
        assert path.is_file(), f"figure {name} did not come back: {outcome.describe()}"
        assert png_size(path) == FIGURE_PX, name


def node_messages(outcome: Outcome, topic: str, node: str) -> int:
    """Messages on `topic`, which `node` publishes (the graph lists a node's topics while it
    lives, so a script that ended is checked by its log instead)."""
    entry = outcome.graph.get(topic)
    assert entry is not None, f"no topic {topic} in the run's graph: {sorted(outcome.graph)}"
    assert node in entry["publishers"], entry
    return entry["messages"]


# ------------------------------------------------------------------------------------ checks
def check_talker_listener(outcome: Outcome) -> None:
    heard = re.findall(r"/listener\S* I heard hello world (\d+\.?\d*)", outcome.log("listener"))
    assert len(heard) >= at_least(outcome, 10, 3.0), outcome.describe()
    # The talker stamps each line with rospy.get_time(): the listener hears them in order.
    stamps = [float(value) for value in heard]
    assert stamps == sorted(stamps) and stamps[-1] - stamps[0] >= 2.0
    chatter = outcome.messages("chatter")
    assert at_least(outcome, 10, 3.0) <= len(chatter) <= 31, len(chatter)
    assert chatter[0][1].data.startswith("hello world ")
    entry = outcome.graph["chatter"]
    assert entry["publishers"] == ["talker"] and entry["subscribers"] == ["listener"]


def check_class_approach(outcome: Outcome) -> None:
    assert sensor_distance(outcome.end.x) == pytest.approx(0.30, abs=0.03)
    assert outcome.metrics["run"]["collisions"] == 0
    assert node_messages(outcome, "Control", "class_approach") >= at_least(outcome, 10, 8.0)


def check_busy_approach(outcome: Outcome) -> None:
    # Forward at 0.1 m/s until the sensor reads 25 cm or less: the loop never sleeps, yet its
    # callback keeps updating the distance and time keeps going.
    assert sensor_distance(outcome.end.x) == pytest.approx(0.25, abs=0.03)
    assert outcome.travelled_between(0.0, 2.0) == travelled(outcome, 0.2, 0.04)
    assert_still_after(outcome, outcome.end.t - 1.0)
    assert outcome.metrics["run"]["collisions"] == 0


def check_wall_follower(outcome: Outcome) -> None:
    assert outcome.end.x - outcome.start.x >= 0.5, outcome.end
    for pose in outcome.poses:
        assert 2.75 <= pose.y <= 3.25, pose  # kept off the south wall (y = 2.5)
    assert outcome.metrics["run"]["collisions"] == 0


def check_square(outcome: Outcome) -> None:
    start, end = outcome.start, outcome.end
    farthest = max(math.hypot(p.x - start.x, p.y - start.y) for p in outcome.poses)
    # Late wakes make a side longer and the turn after it shorter, which opens the square: what
    # they explain is allowed. A side that starts late is shorter, and a turn that ends late
    # turns the rest of the square further in, towards the start: neither takes it farther.
    drift_m = drift_from_late_wakes(outcome, "square_time_now", "cmd_vel")
    lateness = outcome.metrics["nodes"]["square_time_now"]["wake_lateness"]
    assert 0.25 <= farthest <= SQUARE_FARTHEST_M + drift_m, (
        f"farthest {farthest:.3f} m against {SQUARE_FARTHEST_M} m + {drift_m:.3f} m that the "
        f"run's late wakes explain (lateness p50 {lateness.get('p50_s', 0.0) * 1e3:.1f} ms, "
        f"max {lateness.get('max_s', 0.0) * 1e3:.1f} ms)"
    )
    # Open loop: in realtime each side and turn lasts as long as the wall clock says, so a
    # loaded machine's late wake-ups leave a larger gap, as on a real robot.
    realtime = outcome.clock is Clock.REALTIME
    assert math.hypot(end.x - start.x, end.y - start.y) < (0.3 if realtime else 0.15), end
    assert outcome.turned() == pytest.approx(2 * math.pi, abs=1.0 if realtime else 0.6)
    assert_log(outcome, "square_time_now", r"side 4")
    assert_log(outcome, "square_time_now", r"square done")


def check_timer(outcome: Outcome) -> None:
    assert outcome.travelled_between(0.0, 2.2) == travelled(outcome, 0.2, 0.04)
    assert_still_after(outcome, 2.4)
    ticks = int(assert_log(outcome, "timer_driver", r"stopped after (\d+) ticks").group(1))
    assert at_least(outcome, 10, 2.0) <= ticks <= 20
    period = float(assert_log(outcome, "timer_driver", r"timer period (\d\.\d+) s").group(1))
    if outcome.clock is Clock.LOCKSTEP:
        assert period == pytest.approx(0.1, abs=0.001)
    else:
        # rospy.Timer keeps a fixed schedule: after a tick a loaded machine woke late, the next
        # period is that much shorter (0.077 s seen after a 23 ms late tick), so only the
        # order of magnitude is checked here; the tick count above checks the rate.
        assert 0.05 <= period <= 0.3, period


def check_services(outcome: Outcome) -> None:
    assert_log(outcome, "motor_client", r"server says: motors on")
    distance_cm = int(assert_log(outcome, "motor_client", r"distance now (\d+) cm").group(1))
    assert 33 <= distance_cm <= 47  # 0.6 m at the start, minus 2 s at 0.1 m/s
    assert_log(outcome, "motor_client", r"server says: motors off")
    assert_log(outcome, "motor_server", r"enable_motors\(True\)")
    assert_log(outcome, "motor_server", r"enable_motors\(False\)")
    assert outcome.travelled_between(0.0, outcome.end.t) == travelled(outcome, 0.2, 0.05)
    assert_still_after(outcome, 3.0)
    assert any(message.data for _, message in outcome.messages("Buzzer")), "beep never beeped"


def check_params_default(outcome: Outcome) -> None:
    assert_log(outcome, "param_driver", r"unnamed robot: speed 0\.05 m/s, stop at 0\.25 m")
    assert outcome.travelled_between(0.0, 3.0) == travelled(outcome, 0.15, 0.03)


def check_params_set(outcome: Outcome) -> None:
    assert_log(outcome, "param_driver", r"crowbot_7: speed 0\.10 m/s, stop at 0\.25 m")
    assert outcome.travelled_between(0.0, 3.0) == travelled(outcome, 0.30, 0.04)


def check_rosrun_args(outcome: Outcome) -> None:
    # _speed:=0.1 _stop_distance:=0.45 set the private parameters and leave argv clean.
    assert_log(outcome, "param_driver", r"speed 0\.10 m/s, stop at 0\.45 m")
    assert_log(outcome, "param_driver", r"extra arguments: \[\]")
    assert sensor_distance(outcome.end.x) == pytest.approx(0.45, abs=0.03)
    assert_still_after(outcome, outcome.end.t - 1.0)


def check_remap(outcome: Outcome) -> None:
    assert_log(outcome, "remap_forward", r"publishing on /Control")
    assert outcome.travelled_between(0.0, outcome.end.t) == travelled(outcome, 0.2, 0.04)
    # Its 20 Hz for 2 s (the graph lists no publisher: the script has ended).
    assert outcome.graph["Control"]["messages"] >= at_least(outcome, 20, 2.0)
    assert "cmd_vel" not in outcome.recording


def check_odom_turn(outcome: Outcome) -> None:
    assert angle_between(outcome.end.yaw, outcome.start.yaw) == pytest.approx(
        math.pi / 2, abs=math.radians(6)
    )
    assert outcome.travelled_between(0.0, outcome.end.t) < 0.05
    assert_log(outcome, "odom_turn_tf", r"reached yaw")


def check_tf2_distance(outcome: Outcome) -> None:
    assert outcome.travelled_between(0.0, outcome.end.t) == travelled(outcome, 0.3, 0.05)
    assert_log(outcome, "tf2_distance", r"travelled 0\.3\d m")


def check_tf_listener(outcome: Outcome) -> None:
    assert outcome.travelled_between(0.0, outcome.end.t) == travelled(outcome, 0.4, 0.06)
    assert_log(
        outcome, "tf_listener_drive", r"travelled 0\.4\d m, yaw -?\d\.\d deg"
    )  # odom starts at yaw 0


def check_shutdown_hook(outcome: Outcome) -> None:
    # Driving at 0.1 m/s for 1.5 s, then the hook's zero Twist stops the robot at once; the
    # monitor keeps the run going, so without the hook the robot would keep its last command.
    assert outcome.travelled_between(0.0, 1.6) == travelled(outcome, 0.15, 0.03)
    assert_still_after(outcome, 1.8)
    assert_log(outcome, "shutdown_stop", r"stopping the robot")
    seen = re.findall(r"cmd linear (-?\d\.\d\d)", outcome.log("cmd_monitor"))
    assert seen.count("0.10") >= 13 and seen[-1] == "0.00", seen


def check_slow_neighbour(outcome: Outcome) -> None:
    # The driver's 1.5 s are run time, however long its neighbour took to import scipy.
    assert outcome.travelled_between(0.0, 1.6) == travelled(outcome, 0.15, 0.03)
    assert_log(outcome, "shutdown_stop", r"stopping the robot")
    samples = int(assert_log(outcome, "live_plot", r"saving (\d+) samples").group(1))
    assert samples >= at_least(outcome, 20, 3.0)  # Distance at 20 Hz for the whole run
    assert png_size(outcome.artifact("live_plot", "distance.png")) == (800, 400)


def check_wait_for_scan(outcome: Outcome) -> None:
    match = assert_log(outcome, "wait_for_scan", r"first scan after (\d+\.\d+) s with (\d+) beams")
    # The scan comes at 15 Hz: the wait ends at the first one, not at the 5 s timeout.
    assert float(match.group(1)) < (0.1 if outcome.clock is Clock.LOCKSTEP else 1.0)
    first_scan = outcome.messages("scan")[0][1]
    assert int(match.group(2)) == len(first_scan.ranges)
    assert outcome.travelled_between(0.0, outcome.end.t) >= 0.4


def check_crowbot_pid(outcome: Outcome) -> None:
    assert sensor_distance(outcome.end.x) == pytest.approx(0.20, abs=0.03)
    assert outcome.metrics["run"]["collisions"] == 0
    assert_figures(outcome, "crowbot_pid", "pid_error.png", "pid_control.png")


def check_crowbot_light(outcome: Outcome) -> None:
    heading_to_lamp = math.pi / 2
    assert angle_between(outcome.end.yaw, outcome.start.yaw) == pytest.approx(
        heading_to_lamp, abs=math.radians(20)
    )
    assert_figures(outcome, "crowbot_light", "light_error.png", "light_control.png")


def check_tb3_obstacle_stop(outcome: Outcome) -> None:
    north_wall_y = 3.7  # [m]
    assert north_wall_y - outcome.end.y == pytest.approx(0.35, abs=0.06)
    # Stopped at the threshold; the LDS-01's +-15 mm noise may let it creep a centimetre or two.
    assert_still_after(outcome, outcome.end.t - 1.0, within_m=0.04)
    assert_log(outcome, "tb3_obstacle_stop", r"Stop! obstacle at 0\.3\d m")


def check_tb3_closest(outcome: Outcome) -> None:
    # At (3.0, 2.9) the south wall is 0.4 m away, the north wall 0.8 m: it turns to face south.
    assert outcome.end.yaw == pytest.approx(-math.pi / 2, abs=math.radians(10))
    assert outcome.travelled_between(0.0, outcome.end.t) < 0.05


def check_debug_topic(outcome: Outcome) -> None:
    errors = [message.data for _, message in outcome.messages("debug/error")]
    assert len(errors) >= at_least(outcome, 10, 6.0), len(errors)
    assert errors[0] == pytest.approx(0.3, abs=0.02) and abs(errors[-1]) < 0.03
    assert outcome.graph["debug/error"]["subscribers"] == []
    assert sensor_distance(outcome.end.x) == pytest.approx(0.30, abs=0.03)


def check_launch(outcome: Outcome, stop_distance_m: float = 0.30) -> None:
    assert_log(
        outcome,
        "driver",
        rf"crowbot_lab_3: speed 0\.10, stop at {stop_distance_m:.2f} m, kp 0\.80",
    )
    assert sensor_distance(outcome.end.x) == pytest.approx(stop_distance_m, abs=0.03)
    # <group ns="monitor">: its node's relative topic lands in the namespace; <remap>s bring
    # both nodes to the robot's Distance.
    assert_log(outcome, "range_monitor", r"namespace /monitor/, publishing /monitor/too_close")
    assert outcome.graph["Distance"]["subscribers"] == ["driver", "range_monitor"]
    too_close = [message.data for _, message in outcome.messages("monitor/too_close")]
    assert too_close and not too_close[0], too_close[:3]
    # The monitor's threshold is 40 cm: it turns true once the robot is that close.
    assert too_close[-1] is (stop_distance_m < 0.40), too_close[-3:]


def check_launch_with_args(outcome: Outcome) -> None:
    check_launch(outcome, stop_distance_m=0.45)


def check_waypoints(outcome: Outcome) -> None:
    # 0.3 m ahead (+y), a 1.5 rad left turn, 0.3 m ahead again.
    start, end = outcome.start, outcome.end
    assert angle_between(end.yaw, start.yaw) == pytest.approx(1.5, abs=0.2)
    heading = start.yaw + 1.5
    expected_x = start.x + 0.3 * math.cos(start.yaw) + 0.3 * math.cos(heading)
    expected_y = start.y + 0.3 * math.sin(start.yaw) + 0.3 * math.sin(heading)
    assert math.hypot(end.x - expected_x, end.y - expected_y) < 0.1, (end, expected_x, expected_y)
    assert_log(outcome, "waypoint_driver", r"loaded 3 segments")
    trajectory = outcome.artifact("waypoint_driver", "trajectory.csv")
    assert trajectory.is_file(), outcome.describe()
    rows = list(csv.DictReader(io.StringIO(trajectory.read_text())))
    assert len(rows) >= at_least(outcome, 20, 4.5)
    times = [float(row["t"]) for row in rows]
    assert times == sorted(times) and times[-1] - times[0] >= 4.0


def check_yaml_config(outcome: Outcome) -> None:
    assert_log(outcome, "yaml_config_approach", r"'setpoint_m': 0\.35")
    assert sensor_distance(outcome.end.x) == pytest.approx(0.35, abs=0.03)


def check_roslib_open_loop(outcome: Outcome) -> None:
    assert outcome.travelled_between(0.0, outcome.end.t) == travelled(outcome, 0.2, 0.04)
    assert_still_after(outcome, 2.8)
    assert_log(outcome, "roslib_open_loop", r"open loop move done")


def check_ir_scout_commands(outcome: Outcome) -> None:
    assert outcome.travelled_between(0.0, 2.1) == travelled(outcome, 0.24, 0.04)
    assert angle_between(outcome.end.yaw, outcome.start.yaw) == pytest.approx(1.5, abs=0.3)
    assert_still_after(outcome, 3.3)
    assert_log(outcome, "ir_scout_commands", r"sequence finished at t=3\.\d")


def check_reactive(outcome: Outcome) -> None:
    assert sensor_distance(outcome.end.x) == pytest.approx(0.35, abs=0.02)
    # One command per Distance reading: messages flow robot -> node -> robot at 20 Hz.
    distance = outcome.graph["Distance"]["messages"]
    share = REALTIME_SHARE if outcome.clock is Clock.REALTIME else LOCKSTEP_SHARE
    assert node_messages(outcome, "Control", "reactive_callback") >= share * distance
