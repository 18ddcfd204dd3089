"""rospy scripts in the node host: a ROS 1 course script unchanged, sleeps, spin, shutdown."""

from __future__ import annotations

import csv
from pathlib import Path

import matplotlib.pyplot  # noqa: F401  # imported before the node, as the runner's warm pool does
import pytest

from sandbox.msgs.geometry_msgs import Twist
from sandbox.msgs.std_msgs import Int32
from sandbox.protocol import Clock, Exited, Outcome, TopicDecl, Yield
from tests.sandbox.test_host_harness import Parent, crowbot_info, envelope, run

COURSE_SCRIPT = """\
#!/usr/bin/env python3
# Drive towards the wall, stop 20 cm before it, then plot the loop period.
import time

import matplotlib.pyplot as plt
import rospy
from geometry_msgs.msg import Twist
from std_msgs.msg import Int32

distance = 100  # [cm] until the first reading arrives
periods = []
periods_ns = []


def distance_callback(msg):
    global distance
    distance = msg.data


rospy.init_node("wall_stop")
pub = rospy.Publisher("/Control", Twist, queue_size=10)
rospy.Subscriber("/Distance", Int32, distance_callback)
rate = rospy.Rate(10)

twist = Twist()
twist.linear.x = 0.1
last = time.perf_counter()
last_ns = time.perf_counter_ns()
while distance > 20 and not rospy.is_shutdown():
    pub.publish(twist)
    rate.sleep()
    now, now_ns = time.perf_counter(), time.perf_counter_ns()
    periods.append(now - last)
    periods_ns.append(now_ns - last_ns)
    last, last_ns = now, now_ns

pub.publish(Twist())
rospy.loginfo("stopped at %d cm", distance)
rospy.signal_shutdown("done")

plt.plot(periods)
plt.xlabel("loop")
plt.ylabel("period [s]")
plt.savefig("periods.png")
with open("periods.csv", "w") as f:
    f.write("period_s,period_ns\\n")
    for p, p_ns in zip(periods, periods_ns):
        f.write(f"{p!r},{p_ns}\\n")
"""


def approaching_wall(time_s: float) -> list:
    """Distance falls 5 cm per 0.1 s from 100 cm."""
    return [envelope("Distance", Int32(round(100 - 50 * time_s)))]


def test_course_script_runs_unchanged_in_lockstep(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    parent = Parent(COURSE_SCRIPT, tmp_path, filename="wall_stop.py")
    yields, exited = parent.run_lockstep(approaching_wall)

    assert exited.outcome is Outcome.FINISHED, exited.error
    assert exited.reason == "signal_shutdown: done"
    wake_times = [y.wake_at_s for y in yields]
    assert wake_times == pytest.approx([0.1 * k for k in range(1, 17)], abs=1e-12)
    # The loop ends once 20 cm arrives with the wake at 1.6 s.
    assert yields[0].advertised == [TopicDecl("Control", "geometry_msgs/Twist")]
    assert yields[0].subscribed == [TopicDecl("Distance", "std_msgs/Int32")]
    assert all(y.advertised == [] and y.subscribed == [] for y in yields[1:])
    forward = Twist()
    forward.linear.x = 0.1
    for frame in yields:  # each loop's Twist leaves with the sleep that follows it
        assert [(e.topic, Twist.deserialize(e.data)) for e in frame.published] == [
            ("Control", forward)
        ]
    assert [Twist.deserialize(e.data) for e in parent.last_published(exited)] == [Twist()]
    assert "[INFO] [1.600000]: stopped at 20 cm" in capsys.readouterr().out

    files = {artifact.name: artifact.data for artifact in exited.artifacts}
    assert set(files) == {"periods.png", "periods.csv"}
    assert files["periods.png"].startswith(b"\x89PNG\r\n\x1a\n")
    rows = list(csv.DictReader(files["periods.csv"].decode().splitlines()))
    assert len(rows) == 16
    assert [int(row["period_ns"]) for row in rows] == [100_000_000] * 16
    assert [float(row["period_s"]) for row in rows] == pytest.approx([0.1] * 16, abs=1e-9)


def test_realtime_leaves_the_time_modules_clocks_alone(tmp_path: Path) -> None:
    parent = Parent(
        """
        import time
        import rospy
        from std_msgs.msg import Int32
        rospy.init_node("clock")
        pub = rospy.Publisher("Leds", __import__("std_msgs.msg").msg.Int32MultiArray)
        wall = time.time()
        rospy.sleep(0.5)
        assert time.time() > 1e9, "realtime: time.time() is the wall clock"
        assert 2.0 <= rospy.get_time() < 2.0 + 5.0, rospy.get_time()
        """,
        tmp_path,
        info=crowbot_info(clock=Clock.REALTIME, start_time_s=2.0),
    )
    first = parent.next()
    assert isinstance(first, Yield)
    assert first.wake_at_s == pytest.approx(2.5, abs=0.5)
    exited = parent.wake(2.0)  # woken a little early: the node sleeps on until 2.5 s
    assert isinstance(exited, Yield) and exited.wake_at_s == first.wake_at_s
    exited = parent.wake(first.wake_at_s)
    assert isinstance(exited, Exited)
    assert exited.outcome is Outcome.FINISHED, exited.error


def test_shutdown_frame_runs_hooks_and_ends_the_loop(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    parent = Parent(
        """
        import rospy
        rospy.init_node("looper")
        rospy.on_shutdown(lambda: print("hook ran, shutdown =", rospy.is_shutdown()))
        rate = rospy.Rate(5)
        while not rospy.is_shutdown():
            rate.sleep()
        """,
        tmp_path,
    )
    assert parent.next().wake_at_s == pytest.approx(0.2)
    assert parent.wake(0.2).wake_at_s == pytest.approx(0.4)
    exited = parent.shutdown("stop pressed")
    assert exited.outcome is Outcome.SHUTDOWN and exited.reason == "stop pressed"
    assert "hook ran, shutdown = True" in capsys.readouterr().out


def test_the_ros_tutorial_try_except_pattern_ends_as_shutdown(tmp_path: Path) -> None:
    parent = Parent(
        """
        import rospy
        def talker():
            rospy.init_node("talker")
            while not rospy.is_shutdown():
                rospy.sleep(1.0)
        if __name__ == "__main__":
            try:
                talker()
            except rospy.ROSInterruptException:
                pass
        """,
        tmp_path,
    )
    assert parent.next().wake_at_s == pytest.approx(1.0)
    assert parent.shutdown().outcome is Outcome.SHUTDOWN


def test_uncaught_interrupt_counts_as_shutdown(tmp_path: Path) -> None:
    parent = Parent("import rospy\nrospy.init_node('n')\nrospy.Rate(10).sleep()\n", tmp_path)
    parent.next()
    exited = parent.shutdown("run over")
    assert exited.outcome is Outcome.SHUTDOWN and exited.error is None


def test_spin_sleeps_until_messages_and_runs_callbacks_in_order(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    parent = Parent(
        """
        import rospy
        from std_msgs.msg import Int32
        rospy.init_node("echo")
        rospy.Subscriber("Distance", Int32, lambda m, tag: print(tag, m.data), callback_args="d")
        rospy.spin()
        print("after spin")
        """,
        tmp_path,
    )
    first = parent.next()
    assert isinstance(first, Yield) and first.wake_at_s is None
    again = parent.wake(0.05, [envelope("Distance", Int32(7)), envelope("Distance", Int32(8))])
    assert isinstance(again, Yield) and again.wake_at_s is None
    exited = parent.shutdown()
    assert exited.outcome is Outcome.SHUTDOWN
    assert capsys.readouterr().out.splitlines() == ["d 7", "d 8", "after spin"]


def test_wait_for_message_returns_the_next_message(tmp_path: Path) -> None:
    code = """
        import rospy
        from std_msgs.msg import Int32
        rospy.init_node("waiter")
        msg = rospy.wait_for_message("Distance", Int32)
        rospy.Publisher("Leds", __import__("std_msgs.msg").msg.Int32MultiArray).publish(
            data=[msg.data, 0, 0])
        try:
            rospy.wait_for_message("/Button", __import__("std_msgs.msg").msg.Bool, timeout=0.3)
        except rospy.ROSException as error:
            print(error)
            rospy.signal_shutdown("timed out")
    """
    parent = Parent(code, tmp_path)
    frame = parent.next()
    assert frame.wake_at_s is None and frame.subscribed[0].name == "Distance"
    frame = parent.wake(0.05, [])  # woken without the message: keeps waiting
    assert isinstance(frame, Yield) and frame.wake_at_s is None
    frame = parent.wake(0.1, [envelope("Distance", Int32(42))])
    assert isinstance(frame, Yield) and frame.wake_at_s == pytest.approx(0.4)
    assert frame.published[0].topic == "Leds"
    exited = parent.wake(0.4)
    assert exited.outcome is Outcome.FINISHED and exited.reason == "signal_shutdown: timed out"


def test_time_sleep_in_lockstep_yields_in_simulated_time(tmp_path: Path) -> None:
    yields, exited = run(
        """
        import time
        start = time.monotonic()
        time.sleep(0.25)
        time.sleep(0.25)
        print(time.monotonic() - start, time.time())
        """,
        tmp_path,
    )
    assert [y.wake_at_s for y in yields] == pytest.approx([0.25, 0.5])
    assert exited.outcome is Outcome.FINISHED


def test_rate_and_sleep_need_init_node(tmp_path: Path) -> None:
    _, exited = run("import rospy\nrate = rospy.Rate(10)\n", tmp_path)
    assert exited.outcome is Outcome.ERROR
    assert exited.error.type == "ROSInitException" and exited.error.line == 2
    assert "call rospy.init_node('my_node') first" in exited.error.message


def test_params_logging_and_publish_forms(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    _, exited = run(
        """
        import logging
        import rospy
        from std_msgs.msg import Bool, Int32MultiArray
        rospy.init_node("p", anonymous=True)
        gain = rospy.get_param("~gain", 1.0)
        rospy.loginfo("gain=%s missing=%s", gain, rospy.get_param("missing", "dflt"))
        rospy.logdebug("not shown at INFO")
        for _ in range(3):
            rospy.logwarn_once("once only")
        logging.getLogger("mine").warning("through logging")
        leds = rospy.Publisher("Leds", Int32MultiArray, queue_size=1)
        leds.publish(data=[1, 2, 3])
        rospy.Publisher("Buzzer", Bool, queue_size=1).publish(True)
        assert rospy.get_name().startswith("/p_")
        """,
        tmp_path,
        info=crowbot_info(params={"~gain": 2.5}),  # private: a <param> inside <node>
    )
    assert exited.outcome is Outcome.FINISHED, exited.error
    out = capsys.readouterr().out
    assert "[INFO] [0.000000]: gain=2.5 missing=dflt" in out
    assert "not shown" not in out
    assert out.count("once only") == 1
    assert [e.topic for e in exited.published] == ["Leds", "Buzzer"]


def test_launch_style_names_and_parameters_inside_the_sandbox(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # What a launch file gives a node: __name:= and _param:= on its command line, a namespace,
    # run-wide (global) and private parameters. PyYAML types the _param:= values in the sandbox.
    _, exited = run(
        """
        import rospy
        rospy.init_node("ignored_by_launch", anonymous=True)
        print("name", rospy.get_name(), rospy.get_namespace())
        print("speed", repr(rospy.get_param("~speed")), repr(rospy.get_param("~mode")))
        print("global", rospy.get_param("/waypoints"), rospy.search_param("waypoints"))
        print("tree", sorted(rospy.get_param("~").items()))
        try:
            rospy.get_param("~nothing")
        except KeyError as error:
            print("missing", error)
        """,
        tmp_path,
        info=crowbot_info(
            params={"waypoints": [[1, 2]], "~speed": 0.25},
            argv=["_mode:=wall", "_speed:=0.5", "__name:=follower"],
            namespace="/robot1",
        ),
    )
    assert exited.outcome is Outcome.FINISHED, exited.error
    out = capsys.readouterr().out
    assert "name /robot1/follower /robot1/" in out
    assert "speed 0.5 'wall'" in out  # the command line wins over the launch's ~speed
    assert "global [[1, 2]] /waypoints" in out
    assert "tree [('mode', 'wall'), ('speed', 0.5)]" in out
    assert "missing parameter /robot1/follower/nothing (asked as '~nothing') is not set" in out


def test_python_logging_prints_rospy_style_lines(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    import logging

    monkeypatch.setattr(logging.root, "handlers", [])  # as in the child: nothing configured
    _, exited = run(
        """
        import logging
        import time
        time.sleep(1.5)
        logging.getLogger("planner").warning("replanning %d", 3)
        logging.info("root info")
        logging.debug("hidden")
        """,
        tmp_path,
    )
    assert exited.outcome is Outcome.FINISHED, exited.error
    assert capsys.readouterr().out.splitlines() == [
        "[WARN] [1.500000]: planner: replanning 3",
        "[INFO] [1.500000]: root info",
    ]


def test_the_students_own_logging_config_wins(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    import logging

    monkeypatch.setattr(logging.root, "handlers", [])
    _, exited = run(
        """
        import logging, sys
        logging.basicConfig(stream=sys.stdout, level=logging.DEBUG, format="%(message)s!")
        logging.debug("mine")
        """,
        tmp_path,
    )
    assert exited.outcome is Outcome.FINISHED, exited.error
    assert capsys.readouterr().out.splitlines() == ["mine!"]


def test_realtime_time_sleep_lets_callbacks_run(tmp_path: Path) -> None:
    parent = Parent(
        """
        import time
        import rospy
        from std_msgs.msg import Int32
        seen = []
        rospy.init_node("sleeper")
        rospy.Subscriber("Distance", Int32, lambda m: seen.append(m.data))
        time.sleep(3.0)   # longer than the step budget: a sleep, not a computation
        assert seen == [42], seen
        """,
        tmp_path,
        info=crowbot_info(clock=Clock.REALTIME, start_time_s=0.0),
    )
    first = parent.next()
    assert isinstance(first, Yield) and first.wake_at_s == pytest.approx(3.0, abs=0.5)
    frame = parent.wake(1.0, [envelope("Distance", Int32(42))])
    assert isinstance(frame, Yield)
    exited = parent.wake(frame.wake_at_s)
    assert exited.outcome is Outcome.FINISHED, exited.error
