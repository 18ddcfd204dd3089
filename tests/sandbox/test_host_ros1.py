"""ROS 1 semantics course scripts rely on, in the node host: topics before init_node, busy
loops that never sleep, publisher and subscriber queues, shutdown hooks that publish, timers,
wait_for_message, new topic names, and sentences for what is missing."""

from __future__ import annotations

import itertools
from pathlib import Path

import pytest

from sandbox.busy_loop import BUSY_SLICE_NS, FREE_POLLS, POLL_COST_NS
from sandbox.msgs.geometry_msgs import Twist
from sandbox.msgs.std_msgs import Int32
from sandbox.protocol import GraphTopic, Outcome
from tests.sandbox.test_host_harness import Parent, crowbot_info, envelope, run

TALKER_BEFORE_INIT = """
import rospy
from std_msgs.msg import String
pub = rospy.Publisher('chatter', String, queue_size=10)   # before init_node, as the tutorial
rospy.init_node('talker', anonymous=True)
rate = rospy.Rate(10)
for i in range(3):
    pub.publish("hello world %d" % i)
    rate.sleep()
"""


def test_publisher_before_init_node_works_as_in_the_tutorial(tmp_path: Path) -> None:
    yields, exited = run(TALKER_BEFORE_INIT, tmp_path)
    assert exited.outcome is Outcome.FINISHED, exited.error
    assert [y.wake_at_s for y in yields] == pytest.approx([0.1, 0.2, 0.3])
    assert [(d.name, d.type) for d in yields[0].advertised] == [("chatter", "std_msgs/String")]
    assert [e.topic for y in yields for e in y.published] == ["chatter"] * 3


@pytest.mark.parametrize(
    ("code", "message"),
    [
        (
            "pub = rospy.Publisher('Control', Twist, queue_size=1)\npub.publish(Twist())\n",
            "ROS node has not been initialized yet. Please call init_node() first",
        ),
        ("rospy.Rate(10)\n", "rospy.Rate() needs a node: call rospy.init_node("),
        ("rospy.Time.now()\n", "rospy.Time.now() needs a node"),
    ],
)
def test_what_needs_a_node_still_fails_before_init_node(
    tmp_path: Path, code: str, message: str
) -> None:
    _, exited = run("import rospy\nfrom geometry_msgs.msg import Twist\n" + code, tmp_path)
    assert exited.outcome is Outcome.ERROR
    assert message in exited.error.message


BUSY_LOOP = """
import rospy
from geometry_msgs.msg import Twist
rospy.init_node('busy')
pub = rospy.Publisher('Control', Twist, queue_size=5)
cmd = Twist()
cmd.linear.x = 0.1
sent = 0
while not rospy.is_shutdown() and sent < 1000:
    pub.publish(cmd)
    sent += 1
rospy.loginfo("sent %d at %.4f", sent, rospy.get_time())
"""


def test_a_loop_that_never_sleeps_lets_time_pass_and_keeps_the_newest_queue_size(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    yields, exited = run(BUSY_LOOP, tmp_path)
    assert exited.outcome is Outcome.FINISHED, exited.error
    assert len(yields) >= 5  # it yielded as if it slept
    times = [y.wake_at_s for y in yields]
    assert times == sorted(times) and times[0] > 0
    # Every yield after the free polls comes one busy slice of polled time after the last.
    steps = {round((b - a) * 1e9) for a, b in itertools.pairwise(times)}
    assert steps == {BUSY_SLICE_NS}
    # The publisher's queue keeps at most queue_size=5 messages between two yields.
    assert max(len(y.published) for y in yields) == 5
    polls = 2 * 1000 + 1  # is_shutdown() and publish() per message, then get_time()
    per_slice = FREE_POLLS + BUSY_SLICE_NS // POLL_COST_NS  # polls between two busy yields
    slices, rest = divmod(polls, per_slice)
    assert len(yields) == slices
    expected_s = (slices * BUSY_SLICE_NS + max(0, rest - FREE_POLLS) * POLL_COST_NS) / 1e9
    assert f"sent 1000 at {expected_s:.4f}" in capsys.readouterr().out


def test_a_busy_loop_is_reproducible(tmp_path: Path) -> None:
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    first = [y.wake_at_s for y in run(BUSY_LOOP, tmp_path / "a")[0]]
    second = [y.wake_at_s for y in run(BUSY_LOOP, tmp_path / "b")[0]]
    assert first == second


def test_a_time_now_wait_without_sleeping_ends_when_time_has_passed(tmp_path: Path) -> None:
    yields, exited = run(
        """
        import rospy
        from geometry_msgs.msg import Twist
        rospy.init_node('square')
        pub = rospy.Publisher('/Control', Twist, queue_size=1)
        end = rospy.Time.now() + rospy.Duration(0.5)
        while rospy.Time.now() < end:
            pub.publish(Twist())
        rospy.loginfo("side done")
        """,
        tmp_path,
    )
    assert exited.outcome is Outcome.FINISHED, exited.error
    assert yields[-1].wake_at_s == pytest.approx(0.5, abs=0.002)


def test_callbacks_run_during_a_busy_loop(tmp_path: Path) -> None:
    parent = Parent(
        """
        import rospy
        from std_msgs.msg import Int32
        seen = []
        rospy.init_node('poller')
        rospy.Subscriber('Distance', Int32, lambda m: seen.append(m.data))
        while not seen:
            rospy.is_shutdown()
        rospy.loginfo("got %d", seen[0])
        """,
        tmp_path,
    )
    frame = parent.next()
    frame = parent.wake(frame.wake_at_s, [envelope("Distance", Int32(42))])
    assert frame.outcome is Outcome.FINISHED, frame.error


def test_shutdown_hooks_publish_and_a_failing_hook_is_logged(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    parent = Parent(
        """
        import rospy
        from geometry_msgs.msg import Twist
        rospy.init_node('driver')
        pub = rospy.Publisher('Control', Twist, queue_size=1)
        def broken():
            raise RuntimeError("hook bug")
        def stop():
            pub.publish(Twist())
        rospy.on_shutdown(broken)
        rospy.on_shutdown(stop)
        rospy.sleep(1.0)
        rospy.signal_shutdown("done driving")
        with open("after.txt", "w") as f:
            f.write("still running after shutdown")
        """,
        tmp_path,
    )
    _yields, exited = parent.run_lockstep()
    assert exited.outcome is Outcome.FINISHED, exited.error
    assert parent.finishing.reason == "done driving"
    assert [Twist.deserialize(e.data) for e in parent.finishing.published] == [Twist()]
    assert [a.name for a in exited.artifacts] == ["after.txt"]
    out = capsys.readouterr()
    assert "error in shutdown hook" in out.out and "hook bug" in out.out
    assert "RuntimeError" in out.err


def test_wait_for_message_asks_to_be_woken_by_its_topic(tmp_path: Path) -> None:
    parent = Parent(
        """
        import rospy
        from std_msgs.msg import Int32
        rospy.init_node('waiter')
        msg = rospy.wait_for_message('Distance', Int32, timeout=5)
        rospy.loginfo("first %d at %.2f", msg.data, rospy.get_time())
        """,
        tmp_path,
    )
    frame = parent.next()
    assert frame.wake_at_s == pytest.approx(5.0) and frame.wake_on == ["Distance"]
    exited = parent.wake(0.05, [envelope("Distance", Int32(80))])
    assert exited.outcome is Outcome.FINISHED, exited.error


def test_wait_for_message_times_out_with_rospys_sentence(tmp_path: Path) -> None:
    _, exited = run(
        "import rospy\nfrom std_msgs.msg import Int32\nrospy.init_node('w')\n"
        "rospy.wait_for_message('Distance', Int32, timeout=0.5)\n",
        tmp_path,
    )
    assert exited.outcome is Outcome.ERROR
    assert "timeout exceeded while waiting for message on topic /Distance" in exited.error.message


def test_timers_fire_on_their_period_with_timer_events(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    yields, exited = run(
        """
        import rospy
        rospy.init_node('ticker')
        ticks = []
        def tick(event):
            ticks.append(event)
            rospy.loginfo("tick %.2f last %s", event.current_expected.to_sec(),
                          event.last_expected and round(event.last_expected.to_sec(), 2))
        timer = rospy.Timer(rospy.Duration(0.25), tick)
        rospy.Timer(rospy.Duration(0.6), lambda e: rospy.loginfo("once"), oneshot=True)
        rospy.sleep(1.0)
        timer.shutdown()
        rospy.sleep(0.5)
        assert len(ticks) == 4, ticks
        """,
        tmp_path,
    )
    assert exited.outcome is Outcome.FINISHED, exited.error
    assert [y.wake_at_s for y in yields] == pytest.approx([0.25, 0.5, 0.6, 0.75, 1.0, 1.5])
    out = capsys.readouterr().out
    assert "tick 0.25 last None" in out and "tick 1.00 last 0.75" in out
    assert out.count("once") == 1


def test_spin_with_a_timer_wakes_on_the_timer_and_on_messages(tmp_path: Path) -> None:
    parent = Parent(
        """
        import rospy
        from std_msgs.msg import Int32
        rospy.init_node('spinner')
        rospy.Subscriber('Distance', Int32, lambda m: None)
        rospy.Timer(rospy.Duration(0.1), lambda e: None)
        rospy.spin()
        """,
        tmp_path,
    )
    frame = parent.next()
    assert frame.wake_at_s == pytest.approx(0.1) and frame.wake_on == ["Distance"]
    parent.shutdown()


def test_a_subscriber_queue_size_keeps_the_newest(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    parent = Parent(
        """
        import rospy
        from std_msgs.msg import Int32
        rospy.init_node('latest')
        rospy.Subscriber('Distance', Int32, lambda m: rospy.loginfo("one %d", m.data),
                         queue_size=1)
        rospy.Subscriber('Distance', Int32, lambda m: rospy.loginfo("all %d", m.data))
        rospy.sleep(0.1)
        """,
        tmp_path,
    )
    parent.next()
    exited = parent.wake(0.1, [envelope("Distance", Int32(v)) for v in (1, 2, 3)])
    assert exited.outcome is Outcome.FINISHED, exited.error
    out = capsys.readouterr().out
    assert "one 1" not in out and "one 2" not in out and "one 3" in out
    assert all(f"all {v}" in out for v in (1, 2, 3))


def test_any_topic_name_is_accepted_and_a_near_miss_is_warned_once(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    yields, exited = run(
        """
        import rospy
        from std_msgs.msg import Float64, Int32
        rospy.init_node('debugger')
        debug = rospy.Publisher('debug/error', Float64, queue_size=1)
        rospy.Subscriber('distance', Int32, lambda m: None)
        rospy.Subscriber('distance', Int32, lambda m: None)
        debug.publish(0.5)
        rospy.sleep(0.1)
        """,
        tmp_path,
    )
    assert exited.outcome is Outcome.FINISHED, exited.error
    assert [e.topic for e in yields[0].published] == ["debug/error"]
    out = capsys.readouterr().out
    assert out.count("did you mean 'Distance'?") == 1


def test_a_run_that_refuses_new_topics_says_which_exist(tmp_path: Path) -> None:
    _, exited = run(
        "import rospy\nfrom std_msgs.msg import Int32\nrospy.init_node('n')\n"
        "rospy.Subscriber('distance', Int32, print)\n",
        tmp_path,
        info=crowbot_info(allow_new_topics=False),
    )
    assert exited.outcome is Outcome.ERROR
    assert "unknown topic 'distance' on robot crowbot; did you mean 'Distance'?" in (
        exited.error.message
    )


@pytest.mark.parametrize(
    ("code", "message"),
    [
        ("rospy.get_master()\n", "rospy.get_master is not available in RoboDojo nodes"),
        ("rospy.spinOnce()\n", "rospy has no 'spinOnce' in RoboDojo"),
        ("rospy.logwarning('x')\n", "did you mean rospy.logwarn"),
    ],
)
def test_missing_rospy_names_fail_with_a_sentence(tmp_path: Path, code: str, message: str) -> None:
    _, exited = run("import rospy\nrospy.init_node('n')\n" + code, tmp_path)
    assert exited.outcome is Outcome.ERROR
    assert exited.error.type == "AttributeError"
    assert message in exited.error.message


def test_rospy_exceptions_module_and_any_msg(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    parent = Parent(
        """
        import rospy
        from rospy.exceptions import ROSInterruptException
        assert ROSInterruptException is rospy.ROSInterruptException
        rospy.init_node('sniffer')
        rospy.Subscriber('Distance', rospy.AnyMsg,
                         lambda m: rospy.loginfo("%s %d bytes", m._connection_header["type"],
                                                 len(m._buff)))
        rospy.sleep(0.1)
        """,
        tmp_path,
    )
    parent.next()
    exited = parent.wake(0.1, [envelope("Distance", Int32(7))])
    assert exited.outcome is Outcome.FINISHED, exited.error
    assert "std_msgs/Int32 4 bytes" in capsys.readouterr().out


def test_a_loop_spinning_on_time_time_ends_in_lockstep(tmp_path: Path) -> None:
    yields, exited = run(
        """
        import time
        start = time.time()
        while time.time() - start < 0.2:
            pass
        """,
        tmp_path,
    )
    assert exited.outcome is Outcome.FINISHED, exited.error
    assert yields[-1].wake_at_s == pytest.approx(0.2, abs=0.002)


def test_rosrun_arguments_reach_sys_argv_and_myargv_drops_remaps(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    _, exited = run(
        """
        import sys
        import rospy
        rospy.init_node('args')
        rospy.loginfo("argv %s", sys.argv[1:])
        rospy.loginfo("myargv %s", rospy.myargv()[1:])
        rospy.loginfo("resolved %s", rospy.resolve_name('scan'))
        """,
        tmp_path,
        info=crowbot_info(argv=["left", "_speed:=0.2", "scan:=base_scan"]),
    )
    assert exited.outcome is Outcome.FINISHED, exited.error
    out = capsys.readouterr().out
    assert "argv ['left', '_speed:=0.2', 'scan:=base_scan']" in out
    assert "myargv ['left']" in out
    assert "resolved /base_scan" in out


def test_a_realtime_node_clock_follows_the_runs_not_its_own_load() -> None:
    import time as wall

    from sandbox.protocol import Clock
    from sandbox.vclock import NodeClock

    clock = NodeClock(Clock.REALTIME, 0.0)
    wall.sleep(0.05)  # loading: the run's clock has not started yet
    assert clock.now_ns() == 0
    clock.wake(0.1)
    assert 0.1 <= clock.now_s() < 0.13
    wall.sleep(0.05)
    ahead = clock.now_s()  # ~0.15
    clock.wake(0.12)  # the parent's clock is behind ours: it wins, time does not go back
    assert clock.now_s() >= ahead
    wall.sleep(0.06)
    assert clock.now_s() < ahead + 0.05  # no lead kept: ~0.18, not ~0.21


def test_a_bad_remap_on_the_command_line_is_a_sentence_not_a_crash(tmp_path: Path) -> None:
    _, exited = run(
        "import rospy\nrospy.init_node('n')\n",
        tmp_path,
        info=crowbot_info(argv=["scan:=9bad name"]),
    )
    assert exited.outcome is Outcome.ERROR
    assert exited.error.type == "ROSInitException"
    assert exited.error.message.startswith("this node's command line or launch file:")


def test_waiting_for_a_subscriber_without_sleeping_sees_the_graph_change(tmp_path: Path) -> None:
    parent = Parent(
        """
        import rospy
        from std_msgs.msg import String
        rospy.init_node('announcer')
        pub = rospy.Publisher('news', String, queue_size=1)
        while pub.get_num_connections() < 1:
            pass
        pub.publish("someone is listening")
        """,
        tmp_path,
    )
    frame = parent.next()  # a busy yield: the graph comes with the next wake
    graph = [GraphTopic("news", "std_msgs/String", ["announcer"], ["reader"])]
    frame = parent.wake(frame.wake_at_s, [], graph)
    assert frame.outcome is Outcome.FINISHED, frame.error
    assert [e.topic for e in parent.last_published(frame)] == ["news"]
