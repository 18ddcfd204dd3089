"""A spin in a thread of the student's: the ROS 2 way to use Rate.sleep() and Client.call()
from a main loop. Its callbacks run on the node's thread at each of the main loop's waits."""

from __future__ import annotations

from pathlib import Path

import pytest

from sandbox.protocol import Outcome, Yield
from tests.rclpy.harness import decode, envelope, message, published, run, start

SPIN_THREAD = """
import threading
import rclpy
from rclpy.node import Node
from std_msgs.msg import Int32

rclpy.init()
node = Node('rate_loop')
latest = []
node.create_subscription(Int32, 'Distance', lambda m: latest.append(m.data), 10)
out = node.create_publisher(Int32, 'seen', 10)
thread = threading.Thread(target=rclpy.spin, args=(node,), daemon=True)
thread.start()
rate = node.create_rate(4)
for _ in range(6):
    out.publish(Int32(data=len(latest)))
    rate.sleep()
node.destroy_node()
rclpy.shutdown()
thread.join(timeout=1.0)
out_alive = thread.is_alive()
"""


def test_a_spin_thread_feeds_a_rate_loop(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    def sensors(time_s: float) -> list:
        return [envelope("Distance", message("std_msgs/msg/Int32", data=int(time_s * 100)))]

    yields, exited, _ = run(SPIN_THREAD, tmp_path, sensors, spin_period_s=0.05)
    assert exited.outcome is Outcome.FINISHED, exited.error
    seen = [m.data for m in published(yields, exited, "seen")]
    assert seen[0] == 0 and seen == sorted(seen) and seen[-1] >= 4, seen  # the thread starts late
    # the rate keeps 4 Hz: the loop wakes at 0.25 s steps (and for each reading in between)
    assert {y.wake_at_s for y in yields} >= {0.25, 0.5, 0.75, 1.0, 1.25}
    assert "Rate.sleep() works here without spinning" not in capsys.readouterr().out


def test_rate_without_a_spin_thread_works_and_says_how_ros2_needs_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code = """
import rclpy
from rclpy.node import Node
rclpy.init()
node = Node('lonely')
rate = node.create_rate(10)
for _ in range(3):
    rate.sleep()
node.get_logger().info(f'{node.get_clock().now().nanoseconds}')
"""
    yields, exited, _ = run(code, tmp_path)
    assert exited.outcome is Outcome.FINISHED, exited.error
    assert [y.wake_at_s for y in yields] == [0.1, 0.2, 0.3]
    out = capsys.readouterr().out
    assert "[lonely]: 300000000" in out
    assert "Rate.sleep() works here without spinning, but in ROS 2 it returns only" in out


def test_a_multithreaded_executor_in_a_thread_serves_a_sync_call_from_main(
    tmp_path: Path,
) -> None:
    code = """
import threading
import rclpy
from example_interfaces.srv import AddTwoInts
from rclpy.executors import MultiThreadedExecutor
from rclpy.node import Node
from std_msgs.msg import Int64

rclpy.init()
server = Node('server')

def add(request, response):
    response.sum = request.a + request.b
    return response

server.create_service(AddTwoInts, 'add', add)
client_node = Node('client')
client = client_node.create_client(AddTwoInts, 'add')
executor = MultiThreadedExecutor()
executor.add_node(server)
executor.add_node(client_node)
threading.Thread(target=executor.spin, daemon=True).start()
out = client_node.create_publisher(Int64, 'sum', 10)
for a in range(3):
    out.publish(Int64(data=client.call(AddTwoInts.Request(a=a, b=10)).sum))
executor.shutdown()
"""
    yields, exited, _ = run(code, tmp_path)
    assert exited.outcome is Outcome.FINISHED, exited.error
    assert [m.data for m in published(yields, exited, "sum")] == [10, 11, 12]


def test_joining_the_spin_thread_lets_its_callbacks_run(tmp_path: Path) -> None:
    code = """
import threading
import rclpy
from rclpy.executors import MultiThreadedExecutor
from rclpy.node import Node
from std_msgs.msg import Int32

rclpy.init()
node = Node('joiner')
out = node.create_publisher(Int32, 'ticks', 10)
count = [0]

def tick():
    count[0] += 1
    out.publish(Int32(data=count[0]))
    if count[0] == 3:
        rclpy.shutdown()

node.create_timer(0.5, tick)
executor = MultiThreadedExecutor()
executor.add_node(node)
thread = threading.Thread(target=executor.spin)
thread.start()
thread.join()   # waits here while the timer runs, until the callback shuts rclpy down
"""
    yields, exited, _ = run(code, tmp_path)
    assert exited.outcome is Outcome.FINISHED, exited.error
    assert [m.data for m in published(yields, exited, "ticks")] == [1, 2, 3]
    assert [y.wake_at_s for y in yields][:3] == [0.5, 1.0, 1.5]


INTERLEAVED = """
import time
import rclpy
from rclpy.callback_groups import MutuallyExclusiveCallbackGroup, ReentrantCallbackGroup
from rclpy.executors import EXECUTOR
from rclpy.node import Node
from std_msgs.msg import Int32, String

rclpy.init()
node = Node('worker')
events = []
node.create_subscription(Int32, 'Distance', lambda m: events.append(f'd{m.data}'), 10,
                         callback_group=ReentrantCallbackGroup())

def slow():
    events.append('start')
    time.sleep(0.25)
    events.append('end')
    node.create_publisher(String, 'events', 10).publish(String(data=' '.join(events)))
    rclpy.shutdown()

node.create_timer(0.1, slow, callback_group=MutuallyExclusiveCallbackGroup())
executor = EXECUTOR()
executor.add_node(node)
executor.spin()
"""


@pytest.mark.parametrize(
    ("executor", "interleaved"),
    [("MultiThreadedExecutor", True), ("SingleThreadedExecutor", False)],
)
def test_a_sleeping_callback_lets_others_in_only_under_a_multithreaded_executor(
    tmp_path: Path, executor: str, interleaved: bool
) -> None:
    """A reading every 50 ms wakes the node when it waits on Distance (as the run wakes it);
    the timer's callback sleeps from 0.1 s to 0.35 s."""
    parent = start(INTERLEAVED.replace("EXECUTOR", executor), tmp_path, "worker")
    frame, now_ms, yields = parent.next(), 0, []
    while isinstance(frame, Yield):
        yields.append(frame)
        next_reading_ms = now_ms + 50
        wake_ms = None if frame.wake_at_s is None else round(frame.wake_at_s * 1000)
        if "Distance" in (frame.wake_on or ()) or wake_ms is None:
            wake_ms = next_reading_ms if wake_ms is None else min(wake_ms, next_reading_ms)
        now_ms = wake_ms
        readings = []
        if now_ms % 50 == 0:
            reading = message("std_msgs/msg/Int32", data=now_ms // 10)
            readings.append(envelope("Distance", reading))
        frame = parent.wake(now_ms / 1000, readings)
        assert len(yields) < 100
    assert frame.outcome is Outcome.FINISHED, frame.error
    (events,) = [decode(e).data for e in parent.last_published(frame) if e.topic == "events"]
    words = events.split()
    during = words[words.index("start") + 1 : words.index("end")]
    if interleaved:  # rclpy's other threads take the readings while the timer sleeps
        assert len(during) >= 4 and all(word.startswith("d") for word in during), events
    else:  # one thread: the readings wait until the sleeping callback returns
        assert during == [], events
