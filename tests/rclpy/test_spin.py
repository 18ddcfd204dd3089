"""rclpy.spin, spin_once, spin_until_future_complete, timers and the run's end, in the host."""

from __future__ import annotations

from pathlib import Path

import pytest

from sandbox.protocol import Exited, Outcome, Yield
from tests.rclpy.harness import envelope, message, published, run, start

TICKER = """
import rclpy
from rclpy.node import Node
from std_msgs.msg import Int32


class Ticker(Node):
    def __init__(self):
        super().__init__('ticker')
        self.pub = self.create_publisher(Int32, 'ticks', 10)
        self.count = 0
        self.timer = self.create_timer(0.5, self.tick)

    def tick(self):
        self.count += 1
        self.pub.publish(Int32(data=self.get_clock().now().nanoseconds // 1_000_000))
        self.get_logger().info(f'tick {self.count}')
        if self.count == 4:
            rclpy.shutdown()


def main(args=None):
    rclpy.init(args=args)
    node = Ticker()
    rclpy.spin(node)


if __name__ == '__main__':
    main()
"""


def test_a_timer_fires_on_its_period_and_shutdown_in_a_callback_ends_spin(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    yields, exited, _ = run(TICKER, tmp_path, name="ticker")
    assert exited.outcome is Outcome.FINISHED, exited.error
    assert exited.reason == "signal_shutdown: rclpy.shutdown()"
    # The node sleeps exactly until each timer call, and each call sees its own time.
    assert [y.wake_at_s for y in yields] == [0.5, 1.0, 1.5, 2.0]
    assert [m.data for m in published(yields, exited, "ticks")] == [500, 1000, 1500, 2000]
    lines = [line for line in capsys.readouterr().out.splitlines() if "tick" in line]
    assert lines == [
        "[INFO] [0.500000000] [ticker]: tick 1",
        "[INFO] [1.000000000] [ticker]: tick 2",
        "[INFO] [1.500000000] [ticker]: tick 3",
        "[INFO] [2.000000000] [ticker]: tick 4",
    ]


def test_the_run_ending_the_node_raises_external_shutdown_from_spin(tmp_path: Path) -> None:
    code = """
import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from std_msgs.msg import Bool

rclpy.init()
node = Node('waiter')
pub = node.create_publisher(Bool, 'Buzzer', 1)
caught = []
try:
    rclpy.spin(node)
except ExternalShutdownException as error:
    caught.append('external')
except KeyboardInterrupt:
    caught.append('keyboard')
# the usual "stop the robot" after spin still reaches the run
pub.publish(Bool(data=bool(caught == ['external'])))
assert not rclpy.ok()
rclpy.shutdown()  # a no-op after the run ended the node, not an error
"""
    parent = start(code, tmp_path, "waiter")
    first = parent.next()
    assert isinstance(first, Yield) and first.wake_at_s is None  # spin: nothing due
    exited = parent.shutdown("stop pressed")
    assert exited.outcome is Outcome.SHUTDOWN, exited.error
    assert [m.data for m in published([], exited, "Buzzer")] == [True]


def test_course_code_that_only_catches_keyboard_interrupt_still_cleans_up(tmp_path: Path) -> None:
    code = """
import rclpy
from rclpy.node import Node
from std_msgs.msg import Bool

rclpy.init()
node = Node('old_style')
pub = node.create_publisher(Bool, 'Buzzer', 1)
try:
    rclpy.spin(node)
except KeyboardInterrupt:
    pub.publish(Bool(data=True))
node.destroy_node()
rclpy.try_shutdown()
"""
    parent = start(code, tmp_path, "old_style")
    assert isinstance(parent.next(), Yield)
    exited = parent.shutdown()
    assert exited.outcome is Outcome.SHUTDOWN, exited.error
    assert [m.data for m in published([], exited, "Buzzer")] == [True]


def test_an_uncaught_external_shutdown_is_the_runs_stop_not_an_error(tmp_path: Path) -> None:
    code = """
import rclpy
from rclpy.node import Node
rclpy.init()
rclpy.spin(Node('plain'))
"""
    parent = start(code, tmp_path, "plain")
    assert isinstance(parent.next(), Yield)
    exited = parent.shutdown("duration reached")
    assert exited.outcome is Outcome.SHUTDOWN and exited.error is None
    assert exited.reason == "duration reached"


def test_spin_once_runs_at_most_one_callback_and_times_out(tmp_path: Path) -> None:
    code = """
import rclpy
from rclpy.node import Node
from std_msgs.msg import Int32

rclpy.init()
node = Node('looper')
seen = []
node.create_subscription(Int32, 'Distance', lambda m: seen.append(m.data), 10)
pub = node.create_publisher(Int32, 'report', 10)
for _ in range(3):
    before = len(seen)
    rclpy.spin_once(node, timeout_sec=0.25)
    pub.publish(Int32(data=len(seen) - before))
t0 = node.get_clock().now()
rclpy.spin_once(node, timeout_sec=0.3)   # nothing arrives any more: returns at the timeout
waited = (node.get_clock().now() - t0).nanoseconds
pub.publish(Int32(data=waited // 1_000_000))
"""

    def sensors(time_s: float) -> list:
        # three readings arrive together at the first wake, nothing after
        if time_s <= 0.25:
            return [envelope("Distance", message("std_msgs/msg/Int32", data=d)) for d in (1, 2, 3)]
        return []

    yields, exited, _ = run(code, tmp_path, sensors, name="looper")
    assert exited.outcome is Outcome.FINISHED, exited.error
    # one callback per spin_once, the queued messages served one at a time; then a timeout
    assert [m.data for m in published(yields, exited, "report")] == [1, 1, 1, 300]


def test_spin_until_future_complete_returns_at_its_timeout_or_when_done(tmp_path: Path) -> None:
    code = """
import rclpy
from rclpy.node import Node
from rclpy.task import Future
from std_msgs.msg import Int32

rclpy.init()
node = Node('waiter')
pub = node.create_publisher(Int32, 'report', 10)
never = Future()
rclpy.spin_until_future_complete(node, never, timeout_sec=0.7)
pub.publish(Int32(data=node.get_clock().now().nanoseconds // 1_000_000))
soon = Future()
node.create_timer(0.2, lambda: soon.done() or soon.set_result(42))
rclpy.spin_until_future_complete(node, soon)
pub.publish(Int32(data=soon.result()))
pub.publish(Int32(data=node.get_clock().now().nanoseconds // 1_000_000))
"""
    yields, exited, _ = run(code, tmp_path, name="waiter")
    assert exited.outcome is Outcome.FINISHED, exited.error
    assert [m.data for m in published(yields, exited, "report")] == [700, 42, 900]


def test_an_exception_in_a_callback_comes_out_of_spin_at_the_students_line(
    tmp_path: Path,
) -> None:
    code = """
import rclpy
from rclpy.node import Node

rclpy.init()
node = Node('faulty')

def tick():
    return 1 / 0

node.create_timer(0.1, tick)
rclpy.spin(node)
"""
    _, exited, _ = run(code, tmp_path, name="faulty")
    assert exited.outcome is Outcome.ERROR
    assert exited.error.type == "ZeroDivisionError"
    assert exited.error.line == 9  # `return 1 / 0` in the student's file


def test_a_timer_that_falls_behind_skips_the_calls_it_missed(tmp_path: Path) -> None:
    code = """
import time
import rclpy
from rclpy.node import Node
from std_msgs.msg import Int32

rclpy.init()
node = Node('slow')
pub = node.create_publisher(Int32, 'calls', 10)

def tick():
    pub.publish(Int32(data=node.get_clock().now().nanoseconds // 1_000_000))
    if node.get_clock().now().nanoseconds < 300_000_000:
        time.sleep(0.35)   # a slow callback: the 0.2 and 0.3 calls are missed, not made late

node.create_timer(0.1, tick)
for _ in range(4):
    rclpy.spin_once(node)
"""
    yields, exited, _ = run(code, tmp_path, name="slow")
    assert exited.outcome is Outcome.FINISHED, exited.error
    assert [m.data for m in published(yields, exited, "calls")] == [100, 450, 500, 600]


def test_rclpy_before_init_fails_as_rclpy_does(tmp_path: Path) -> None:
    _, exited, _ = run("import rclpy\nfrom rclpy.node import Node\nNode('early')\n", tmp_path)
    assert exited.outcome is Outcome.ERROR
    assert exited.error.type == "NotInitializedException"
    assert exited.error.message == "rclpy.init() has not been called. msg:cannot create node"


def test_init_twice_fails_as_rclpy_does(tmp_path: Path) -> None:
    _, exited, _ = run("import rclpy\nrclpy.init()\nrclpy.init()\n", tmp_path)
    assert exited.outcome is Outcome.ERROR
    assert exited.error.type == "RuntimeError"
    assert exited.error.message == "Context.init() must only be called once"
    assert isinstance(exited, Exited)


def test_async_callbacks_await_a_service_response(tmp_path: Path) -> None:
    code = """
import rclpy
from example_interfaces.srv import AddTwoInts
from rclpy.node import Node
from std_msgs.msg import Int64

rclpy.init()
node = Node('asker')

def add(request, response):
    response.sum = request.a + request.b
    return response

node.create_service(AddTwoInts, 'add', add)
client = node.create_client(AddTwoInts, 'add')
out = node.create_publisher(Int64, 'sum', 10)

async def tick():
    response = await client.call_async(AddTwoInts.Request(a=40, b=2))
    out.publish(Int64(data=response.sum))
    rclpy.shutdown()

node.create_timer(0.1, tick)
rclpy.spin(node)
"""
    yields, exited, _ = run(code, tmp_path, name="asker")
    assert exited.outcome is Outcome.FINISHED, exited.error
    assert [m.data for m in published(yields, exited, "sum")] == [42]


def test_spin_once_serves_each_ready_subscription_before_serving_one_twice(
    tmp_path: Path,
) -> None:
    code = """
import rclpy
from rclpy.node import Node
from std_msgs.msg import Bool, Int32, String

rclpy.init()
node = Node('fair')
order = []
node.create_subscription(Int32, 'Distance', lambda m: order.append('d'), 10)
node.create_subscription(Bool, 'Button', lambda m: order.append('b'), 10)
rclpy.spin_once(node, timeout_sec=0.2)  # waits for the first burst, serves one
for _ in range(3):
    rclpy.spin_once(node, timeout_sec=0)
node.create_publisher(String, 'order', 10).publish(String(data=''.join(order)))
"""

    def sensors(time_s: float) -> list:
        return [
            envelope("Distance", message("std_msgs/msg/Int32", data=1)),
            envelope("Distance", message("std_msgs/msg/Int32", data=2)),
            envelope("Button", message("std_msgs/msg/Bool", data=True)),
            envelope("Button", message("std_msgs/msg/Bool", data=False)),
        ]

    yields, exited, _ = run(code, tmp_path, sensors, name="fair")
    assert exited.outcome is Outcome.FINISHED, exited.error
    assert [m.data for m in published(yields, exited, "order")] == ["dbdb"]


def test_a_timer_of_period_zero_is_a_busy_loop_that_lets_time_pass(tmp_path: Path) -> None:
    code = """
import rclpy
from rclpy.node import Node
from std_msgs.msg import Int64

rclpy.init()
node = Node('busy')
calls = [0]

def tick():
    calls[0] += 1
    if node.get_clock().now().nanoseconds >= 50_000_000:
        out = node.create_publisher(Int64, 'calls', 10)
        out.publish(Int64(data=calls[0]))
        rclpy.shutdown()

node.create_timer(0.0, tick)
rclpy.spin(node)
"""
    yields, exited, _ = run(code, tmp_path, name="busy")
    assert exited.outcome is Outcome.FINISHED, exited.error
    (calls,) = [m.data for m in published(yields, exited, "calls")]
    # Each call polls twice (the executor's turn and clock.now()); 100 free polls per wake,
    # then 20 us each with a wake every 5 ms: 50 ms of simulated time is about 1750 calls.
    assert 1500 < calls < 2000, calls
