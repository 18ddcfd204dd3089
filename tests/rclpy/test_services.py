"""Services and clients: calls within one process, and across the run's service topics."""

from __future__ import annotations

from pathlib import Path

from sandbox.protocol import GraphTopic, Outcome, Yield
from sandbox.services import REPLY_PREFIX, request_topic
from tests.rclpy.harness import decode, envelope, message, published, run, start

SERVER_AND_CLIENT = """
import rclpy
from example_interfaces.srv import AddTwoInts
from rclpy.node import Node
from std_msgs.msg import Int64

rclpy.init()
server = Node('server')

def add(request, response):
    response.sum = request.a + request.b
    server.get_logger().info(f'Incoming request a: {request.a} b: {request.b}')
    return response

server.create_service(AddTwoInts, 'add_two_ints', add)
client_node = Node('client')
client = client_node.create_client(AddTwoInts, 'add_two_ints')
assert client.wait_for_service(timeout_sec=1.0)
future = client.call_async(AddTwoInts.Request(a=41, b=1))
from rclpy.executors import SingleThreadedExecutor
executor = SingleThreadedExecutor()
executor.add_node(server)
executor.add_node(client_node)
executor.spin_until_future_complete(future, timeout_sec=1.0)
out = client_node.create_publisher(Int64, 'sum', 10)
out.publish(Int64(data=future.result().sum))
out.publish(Int64(data=client.call(AddTwoInts.Request(a=2, b=3)).sum))
"""


def test_a_service_in_the_same_file_answers_call_async_and_call(tmp_path: Path) -> None:
    yields, exited, _ = run(SERVER_AND_CLIENT, tmp_path)
    assert exited.outcome is Outcome.FINISHED, exited.error
    assert [m.data for m in published(yields, exited, "sum")] == [42, 5]


def test_a_callback_that_returns_nothing_fails_with_a_sentence(tmp_path: Path) -> None:
    code = SERVER_AND_CLIENT.replace("    return response\n", "")
    _, exited, _ = run(code, tmp_path)
    assert exited.outcome is Outcome.ERROR
    assert exited.error.type == "TypeError"
    assert exited.error.message.startswith(
        "the callback of service '/add_two_ints' returned None: it must return the response"
    )


def test_a_sync_call_inside_a_single_threaded_callback_says_it_would_deadlock(
    tmp_path: Path,
) -> None:
    code = """
import rclpy
from example_interfaces.srv import AddTwoInts
from rclpy.node import Node

rclpy.init()
node = Node('caller')
client = node.create_client(AddTwoInts, 'add_two_ints')

def tick():
    client.call(AddTwoInts.Request(a=1, b=2))

node.create_timer(0.1, tick)
rclpy.spin(node)
"""
    _, exited, _ = run(code, tmp_path)
    assert exited.outcome is Outcome.ERROR
    assert exited.error.type == "RuntimeError"
    assert "inside a callback would block for ever in ROS 2" in exited.error.message
    assert exited.error.line == 11


def test_a_reentrant_client_in_a_multithreaded_executor_may_call_from_a_timer(
    tmp_path: Path,
) -> None:
    code = """
import rclpy
from example_interfaces.srv import AddTwoInts
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.executors import MultiThreadedExecutor
from rclpy.node import Node
from std_msgs.msg import Int64

rclpy.init()
node = Node('caller')

def add(req, res):
    res.sum = req.a * 10 + req.b
    return res

node.create_service(AddTwoInts, 'add', add)
client = node.create_client(AddTwoInts, 'add', callback_group=ReentrantCallbackGroup())
out = node.create_publisher(Int64, 'sum', 10)

def tick():
    out.publish(Int64(data=client.call(AddTwoInts.Request(a=4, b=2)).sum))
    rclpy.shutdown()

node.create_timer(0.1, tick, callback_group=ReentrantCallbackGroup())
executor = MultiThreadedExecutor()
executor.add_node(node)
executor.spin()
"""
    yields, exited, _ = run(code, tmp_path)
    assert exited.outcome is Outcome.FINISHED, exited.error
    assert [m.data for m in published(yields, exited, "sum")] == [42]


def test_a_call_to_another_node_goes_over_the_service_topics(tmp_path: Path) -> None:
    code = """
import rclpy
from example_interfaces.srv import AddTwoInts
from rclpy.node import Node
from std_msgs.msg import Int64

rclpy.init()
node = Node('client')
client = node.create_client(AddTwoInts, 'add_two_ints')
while not client.wait_for_service(timeout_sec=0.5):
    node.get_logger().info('service not available, waiting again...')
future = client.call_async(AddTwoInts.Request(a=41, b=1))
rclpy.spin_until_future_complete(node, future)
node.create_publisher(Int64, 'sum', 10).publish(Int64(data=future.result().sum))
"""
    parent = start(code, tmp_path, "client")
    frame = parent.next()
    assert isinstance(frame, Yield)  # wait_for_service looks at the graph: none yet
    graph = [
        GraphTopic(request_topic("add_two_ints"), "robodojo_msgs/msg/ServiceCall", [], ["server"])
    ]
    frame = parent.wake(0.25, [], graph)
    assert isinstance(frame, Yield)
    calls = [e for e in frame.published if e.topic == request_topic("add_two_ints")]
    assert len(calls) == 1 and calls[0].type == "robodojo_msgs/msg/ServiceCall"
    call = decode(calls[0])
    assert call.reply_to == REPLY_PREFIX + "client"
    request = message("example_interfaces/srv/AddTwoInts_Request").deserialize(bytes(call.request))
    assert (request.a, request.b) == (41, 1)
    response = message("example_interfaces/srv/AddTwoInts_Response", sum=42)
    reply = message(
        "robodojo_msgs/msg/ServiceReply", id=call.id, ok=True, response=response.serialize()
    )
    exited = parent.wake(0.26, [envelope(call.reply_to, reply)])
    while isinstance(exited, Yield):
        exited = parent.wake(0.3)
    assert exited.outcome is Outcome.FINISHED, exited.error
    sums = [decode(e).data for e in parent.last_published(exited) if e.topic == "sum"]
    assert sums == [42]
