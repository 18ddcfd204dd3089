"""A worker's publisher sends every run's batch of a round together (issue 16: per run, a loaded
cluster worker's Redis round trips made a round of 50 runs take 100+ ms and viewers got a third
of their frames), and one bad run or one bad batch never costs the others their traffic."""

from __future__ import annotations

import logging
import math

from server.workers.host import RunHost, _Hosted
from server.workers.local_worker import PipeOutlet
from server.workers.outbox import Outbox
from server.workers.wire import LiveBatch, RunJob, Sample, dumps, loads


class _Outlet:
    def __init__(self, fails: bool = False) -> None:
        self.rounds: list[list[LiveBatch]] = []
        self.fails = fails

    def publish_round(self, batches) -> None:
        self.rounds.append(list(batches))
        if self.fails:
            raise RuntimeError("an outlet that broke its promise not to raise")


def _host(outlet: _Outlet) -> RunHost:
    made = RunHost.__new__(RunHost)  # only what a publisher round touches
    made.outlet = outlet
    made.worker_id = "test:1"
    return made


def _hosted(run_id: str) -> _Hosted:
    job = RunJob(run_id, user_id="student", spec=None, run_dir="/nowhere")  # spec: not read
    return _Hosted(job=job, outbox=Outbox(store=None, run_id=run_id, wake=lambda: None))


def test_a_round_goes_out_in_one_call_with_every_run_that_had_something() -> None:
    outlet = _Outlet()
    runs = [_hosted(f"run{n}") for n in range(3)]
    runs[0].outbox.on_message("Distance", "std_msgs/Int32", 5, b"\x01\x00\x00\x00")
    runs[2].outbox.finish([{"type": "state", "state": "finished"}])
    host = _host(outlet)
    host._publish_round(runs, now_s=10.0)  # the first round: every run's status is due
    assert len(outlet.rounds) == 1
    assert [b.run_id for b in outlet.rounds[0]] == ["run0", "run1", "run2"]
    assert outlet.rounds[0][0].samples[0].topic == "Distance"
    assert outlet.rounds[0][2].final and runs[2].published.is_set()
    assert not runs[0].published.is_set()

    host._publish_round(runs, now_s=10.05)  # nothing new, no status due, run2 already ended
    assert len(outlet.rounds) == 1
    runs[1].outbox.on_logs("controller", ["hello"])
    host._publish_round(runs, now_s=10.1)
    assert [b.run_id for b in outlet.rounds[1]] == ["run1"]


def test_a_run_whose_batch_cannot_be_made_does_not_hold_back_the_others(caplog) -> None:
    outlet = _Outlet()
    broken = _hosted("broken")
    broken.outbox.take = lambda now_s: 1 / 0  # type: ignore[method-assign]
    fine = _hosted("fine")
    with caplog.at_level(logging.ERROR, logger="robodojo.workers"):
        _host(outlet)._publish_round([broken, fine], now_s=1.0)
    assert [b.run_id for b in outlet.rounds[0]] == ["fine"]
    assert "run broken: live batch not sent" in caplog.text


def test_a_final_batch_counts_as_sent_even_when_the_outlet_raises(caplog) -> None:
    ending = _hosted("ending")
    ending.outbox.finish([])
    with caplog.at_level(logging.ERROR, logger="robodojo.workers"):
        _host(_Outlet(fails=True))._publish_round([ending], now_s=1.0)
    assert ending.published.is_set()  # the run's thread waits on it to end
    assert "a round of 1 live batches was not sent" in caplog.text


def test_the_pipe_carries_a_round_as_one_message_and_leaves_out_a_batch_json_refuses(caplog):
    sent: list[bytes] = []
    outlet = PipeOutlet(lambda message: sent.append(dumps(message)))
    good = LiveBatch("good", samples=(Sample("Light", "std_msgs/Int32", 1, b"\x07", 0.0),))
    bad = LiveBatch("bad", events=({"type": "log", "line": "x", "value": math.nan},))
    also = LiveBatch("also", events=({"type": "log", "line": "y"},))
    with caplog.at_level(logging.ERROR, logger="robodojo.workers"):
        outlet.publish_round([good, bad, also])
    assert len(sent) == 1
    message = loads(sent[0])
    assert message["op"] == "batches"
    assert [b["run_id"] for b in message["batches"]] == ["good", "also"]
    assert "run bad: a live batch is not JSON" in caplog.text
