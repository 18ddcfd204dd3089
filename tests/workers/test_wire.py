"""The wire between web processes and workers: every job, batch and command survives a round
trip through JSON unchanged, and what is not one of them is refused with a sentence."""

from __future__ import annotations

import pytest

from sandbox.protocol import Api, Clock
from server.runs.commands import Button, InjectFault, Light, Stop
from server.runs.faults import FaultKind
from server.runs.spec import NodeSpec, RunSpec
from server.workers.wire import (
    CommandAnswer,
    CommandRequest,
    LiveBatch,
    RunJob,
    RunStatus,
    Sample,
    WireError,
    answer_from_json,
    answer_to_json,
    batch_from_json,
    batch_to_json,
    dumps,
    job_from_json,
    job_to_json,
    loads,
    request_from_json,
    request_to_json,
)


def full_spec() -> RunSpec:
    node = NodeSpec(
        name="follower",
        code="import rospy\nrospy.init_node('f')\n",
        filename="follower.py",
        api=Api.ROSPY,
        params={"gain": 0.5, "names": ["a", "b"]},
        remaps=(("scan", "/base_scan"),),
        args=("--fast",),
        namespace="/robot1",
        ros_version=1,
    )
    return RunSpec(
        robot="crowbot",
        world="crowbot_corridor",
        nodes=(node,),
        clock=Clock.REALTIME,
        duration_s=12.5,
        seed=7,
        spawn="start",
        initial_pose=(0.1, -0.2, 1.5),
        light_position=(1.0, 2.0),
        goal=(3.0, 4.0, 0.0),
        params={"/rate": 10},
        script=(
            (1.0, Button(True)),
            (2.5, Light(0.5, 0.25)),
            (3.0, InjectFault(FaultKind.FREEZE_TOPIC, "scan", 0.5)),
        ),
        builtin_nodes=("teleop",),
        files=(("data/log.csv", b"\x00\xff,1\n"),),
        explicit_ros_version=1,
    )


def through_the_wire(data: dict) -> dict:
    return loads(dumps(data))


def test_a_job_round_trips_with_every_field_of_its_spec() -> None:
    job = RunJob("r1", "u1", full_spec(), "/data/runs/r1", "crowbot_distance_pid", "crowbot-1", 5.0)
    assert job_from_json(through_the_wire(job_to_json(job))) == job


def test_a_batch_round_trips_with_binary_samples_events_and_status() -> None:
    status = RunStatus(
        "r1", "running", "", 3.5, 2, {"n": {"p50_ms": 100.0}}, 1, {"n": ["hello"]},
        {"nodes": []}, [{"name": "lamp", "x": 1.0, "y": 2.0, "z": 0.3, "intensity": 1.0,
                         "movable": True}], "host:42", 1e9,
    )  # fmt: skip
    batch = LiveBatch(
        "r1",
        (Sample("scan", "sensor_msgs/LaserScan", 5_000_000, bytes(range(256)), 1e9, 3),),
        ({"type": "log", "node": "n", "line": "hello"}, {"type": "state", "state": "running"}),
        status,
        final=True,
    )
    assert batch_from_json(through_the_wire(batch_to_json(batch))) == batch


def test_commands_and_answers_round_trip() -> None:
    request = CommandRequest("q1", "r1", Stop("stopped by the instructor"))
    assert request_from_json(through_the_wire(request_to_json(request))) == request
    answer = CommandAnswer("q1", False, "a realtime run cannot be paused")
    assert answer_from_json(through_the_wire(answer_to_json(answer))) == answer


@pytest.mark.parametrize(
    ("decode", "data", "words"),
    [
        (job_from_json, [], "must be a JSON object"),
        (job_from_json, {"wire": 99}, "wire version 99"),
        (job_from_json, {"wire": 1, "run_id": "r"}, "lacks"),
        (batch_from_json, {"run_id": "r", "samples": [["t", "x", 1, "%%%", 1.0, 0]]}, "base64"),
        (batch_from_json, {"run_id": "r", "status": {"run_id": "r"}}, "lacks"),
        (request_from_json, {"request_id": "q", "run_id": "r", "command": {"op": "rm -rf"}},
         "not a command"),
        (answer_from_json, "yes", "must be a JSON object"),
    ],
)  # fmt: skip
def test_malformed_messages_are_refused_with_a_sentence(decode, data, words) -> None:
    with pytest.raises(WireError, match=words):
        decode(data)


def test_a_spec_with_values_json_cannot_carry_is_refused_before_it_is_queued() -> None:
    spec = full_spec()
    bad = RunSpec(robot=spec.robot, world=spec.world, nodes=spec.nodes, params={"x": object()})
    with pytest.raises(WireError, match="cannot cross to a worker as JSON"):
        job_to_json(RunJob("r", "u", bad, "/tmp/r"))


def test_pickles_are_not_json() -> None:
    import pickle

    with pytest.raises(WireError, match="not JSON"):
        loads(pickle.dumps({"run_id": "r"}))


@pytest.mark.parametrize("raw", [b'{"x": NaN}', b'{"x": Infinity}', b'{"x": 1', b"", "\ufeff{}"])
def test_what_dumps_would_never_write_is_not_read_either(raw) -> None:
    with pytest.raises(WireError, match="not JSON"):
        loads(raw)


def test_loads_reads_back_what_dumps_wrote() -> None:
    value = {"run_id": "r", "samples": [["odom", "nav_msgs/Odometry", 2**62, "AAE=", 1.5, 0]]}
    assert loads(dumps(value)) == value
    assert loads(dumps(value).decode()) == value


def test_the_lab_s_redis_clients_parse_replies_with_hiredis():
    """A web process reads every viewed run's live batches from pub/sub: redis-py's C parser
    takes 9 us a message where its own takes 15 (issue 16). redis-py falls back to its own
    without a word when hiredis is missing, so say it here."""
    from redis._parsers import _HiredisParser

    from server.workers.queue import redis_client

    pool = redis_client("redis://127.0.0.1:1/0").connection_pool  # connects at first command
    connection = pool.connection_class(**pool.connection_kwargs)
    assert isinstance(connection._parser, _HiredisParser), type(connection._parser)
