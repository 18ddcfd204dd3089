"""The embedded lab's default (issue 16): `robodojo serve` spreads runs over worker processes of
its machine. A real server with two worker processes, driven over HTTP and the websocket like a
browser: the student flow, live view and commands across the process boundary, and a worker
killed with SIGKILL mid-run (its run fails "worker lost", seen live; the other carries on; the
next run starts)."""

from __future__ import annotations

import json
import os
import signal
import time
from collections.abc import Iterator

import pytest
from websockets.sync.client import connect

from server.store import runs as run_store
from server.store.db import Store
from tests.api.conftest import (
    LabServer,
    start_crowbot_run,
    start_server,
    stop_server,
    wait_for_end,
)
from tests.waiting import wait_until

WORKERS = 2
LOST_WITHIN_S = 10.0  # [s] the bound: a lost worker's run reads "failed" by then
ORPHANS_GONE_WITHIN_S = 5.0  # [s] a dead worker's sandbox processes are killed by then


@pytest.fixture(scope="module")
def lab(tmp_path_factory) -> Iterator[LabServer]:
    server = start_server(
        tmp_path_factory.mktemp("local-workers"), {"ROBODOJO_WORKERS": str(WORKERS)}
    )
    yield server
    stop_server(server)


@pytest.fixture(autouse=True)
def _close_clients(lab) -> Iterator[None]:
    yield
    lab.close_clients()


def ws_connect(lab: LabServer, client, run_id: str):
    cookies = "; ".join(f"{k}={v}" for k, v in client.cookies.items())
    url = lab.url.replace("http", "ws", 1) + f"/api/runs/{run_id}/live"
    return connect(url, additional_headers={"Cookie": cookies}, open_timeout=30)


def receive_until(ws, predicate, timeout_s: float = 30.0) -> list[dict]:
    frames: list[dict] = []
    deadline = time.monotonic() + timeout_s
    while True:
        remaining = deadline - time.monotonic()
        assert remaining > 0, frames[-10:]
        frame = json.loads(ws.recv(timeout=remaining))
        frames.append(frame)
        if predicate(frame):
            return frames


def worker_of(lab: LabServer, run_id: str) -> str | None:
    store = Store.open(lab.database_url)
    try:
        with store.session() as db:
            record = run_store.get(db, run_id)
            return record.worker_id if record is not None else None
    finally:
        store.close()


def server_workers(lab: LabServer) -> list[dict]:
    answer = lab.admin().get("/api/admin/status")
    assert answer.status_code == 200, answer.text
    return answer.json()["runs"]["workers"]


def test_a_run_executes_on_a_worker_process_and_ends_stored_and_judged(lab):
    workers = server_workers(lab)
    pids = {int(w["id"].rsplit(":", 1)[1]) for w in workers}
    # The web process itself, for real robots' runs only: labelled so, with no capacity to
    # add to the workers' (it was listed as a third worker of capacity max_runs_total).
    (web,) = [w for w in workers if int(w["id"].rsplit(":", 1)[1]) == lab.process.pid]
    assert web["role"] == "web process: real robots' runs" and web["capacity"] is None, web
    assert len(pids - {lab.process.pid}) == WORKERS, workers
    assert [w["role"] for w in workers].count("worker process") == WORKERS, workers
    # The web process keeps no warm sandbox; the workers do, and the status counts theirs.
    wait_until(
        lambda: lab.admin().get("/api/admin/status").json()["runs"]["warm_pool"] >= WORKERS,
        60,
        "the workers' warm sandboxes counted",
    )
    student = lab.student("flow")
    run_id = start_crowbot_run(student, clock="lockstep", duration_s=2.0)
    run = wait_for_end(student, run_id)
    assert run["state"] == "finished", run
    assert run["nodes"]["driver"]["wakes"] > 10
    worker = worker_of(lab, run_id)
    assert worker is not None and int(worker.rsplit(":", 1)[1]) in pids - {lab.process.pid}
    logs = student.get(f"/api/runs/{run_id}/logs").json()["nodes"]
    assert logs["driver"] and logs["driver"][0].startswith("distance")
    assert student.get(f"/api/runs/{run_id}/recording.mcap").status_code == 200


def test_live_view_logs_and_commands_cross_to_the_worker(lab):
    student = lab.student("live")
    run_id = start_crowbot_run(student, clock="realtime", duration_s=60.0)
    with ws_connect(lab, student, run_id) as ws:
        assert json.loads(ws.recv(timeout=30))["type"] == "snapshot"
        ws.send(json.dumps({"id": 1, "op": "subscribe", "topic": "Distance", "max_rate_hz": 20}))
        frames = receive_until(
            ws, lambda f: f["type"] == "telemetry" and f["topic"] == "Distance" and f["time_s"] > 1
        )
        telemetry = [f for f in frames if f["type"] == "telemetry"]
        assert all(isinstance(f["msg"]["data"], int) for f in telemetry)
        # Produced on the worker, stamped there: delivery end to end stays short.
        assert all(0 <= time.time() - f["wall_s"] < 30 for f in telemetry)
        receive_until(ws, lambda f: f["type"] == "log" and f["line"].startswith("distance"))
        ws.send(json.dumps({"id": "b", "op": "button", "pressed": True}))
        receive_until(ws, lambda f: f.get("id") == "b" and f["type"] == "ack")
        ws.send(json.dumps({"id": "p", "op": "pause"}))  # realtime: refused, with the reason
        refused = receive_until(ws, lambda f: f.get("id") == "p")[-1]
        assert refused["type"] == "error" and "only a lockstep" in refused["detail"]
        live = student.get(f"/api/runs/{run_id}").json()
        assert live["state"] == "running" and "driver" in live["nodes_live"]
        assert "driver" in student.get(f"/api/runs/{run_id}/graph").json()["nodes"]
        ws.send(json.dumps({"id": "s", "op": "stop"}))
        ending = receive_until(ws, lambda f: f["type"] == "end")
        assert ending[-1]["state"] == "interrupted"
    run = wait_for_end(student, run_id)
    assert run["state"] == "interrupted" and "stopped by the user" in run["reason"]


def test_a_lockstep_run_pauses_and_resumes_over_http(lab):
    student = lab.student("pauser")
    run_id = start_crowbot_run(student, clock="lockstep", duration_s=600.0)
    wait_until(
        lambda: student.get(f"/api/runs/{run_id}").json()["state"] == "running", 30, "running"
    )
    assert student.post(f"/api/runs/{run_id}/pause").status_code == 200
    wait_until(lambda: student.get(f"/api/runs/{run_id}").json()["state"] == "paused", 30, "paused")
    again = student.post(f"/api/runs/{run_id}/pause")
    assert again.status_code == 409 and "already paused" in again.json()["detail"]
    assert student.post(f"/api/runs/{run_id}/resume").status_code == 200
    wait_until(
        lambda: student.get(f"/api/runs/{run_id}").json()["state"] == "running", 30, "resumed"
    )
    assert student.post(f"/api/runs/{run_id}/stop").status_code == 200
    assert wait_for_end(student, run_id)["state"] == "interrupted"


@pytest.mark.slow
def test_a_killed_worker_fails_its_run_live_and_spares_the_other(lab):
    first, second = lab.student("kill-a"), lab.student("kill-b")
    doomed = start_crowbot_run(first, clock="realtime", duration_s=120.0)
    spared = start_crowbot_run(second, clock="realtime", duration_s=120.0)
    for client, run_id in ((first, doomed), (second, spared)):
        wait_until(
            lambda c=client, r=run_id: c.get(f"/api/runs/{r}").json()["state"] == "running",
            60,
            f"run {run_id} running",
        )
    doomed_worker, spared_worker = worker_of(lab, doomed), worker_of(lab, spared)
    assert doomed_worker and spared_worker and doomed_worker != spared_worker  # least loaded
    with ws_connect(lab, first, doomed) as ws:
        assert json.loads(ws.recv(timeout=30))["type"] == "snapshot"
        os.kill(int(doomed_worker.rsplit(":", 1)[1]), signal.SIGKILL)
        killed_at = time.monotonic()
        frames = receive_until(ws, lambda f: f["type"] == "end", timeout_s=LOST_WITHIN_S + 5)
        seen_after_s = time.monotonic() - killed_at
    assert frames[-1]["state"] == "failed" and "worker lost" in frames[-1]["reason"]
    assert seen_after_s < LOST_WITHIN_S, seen_after_s
    stored = first.get(f"/api/runs/{doomed}").json()
    assert stored["state"] == "failed" and "worker lost" in stored["reason"]
    # The other worker's run carries on.
    before = second.get(f"/api/runs/{spared}").json()["time_s"]
    wait_until(
        lambda: second.get(f"/api/runs/{spared}").json()["time_s"] > before + 0.5,
        30,
        "the other worker's run goes on",
    )
    assert second.get(f"/api/runs/{spared}").json()["state"] == "running"
    # The lost worker is replaced, and the next run starts and ends.
    wait_until(lambda: len(server_workers(lab)) == WORKERS + 1, 60, "a new worker process")
    assert second.post(f"/api/runs/{spared}/stop").status_code == 200
    assert wait_for_end(second, spared)["state"] == "interrupted"
    next_run = start_crowbot_run(first, clock="lockstep", duration_s=1.0)
    assert wait_for_end(first, next_run)["state"] == "finished"


@pytest.mark.slow
def test_a_killed_worker_leaves_no_sandbox_process_behind(lab):
    kill_a_worker_mid_run_and_expect_no_orphans(lab)


@pytest.mark.slow
def test_a_killed_worker_leaves_no_unsandboxed_node_behind(tmp_path):
    # Without bubblewrap nothing ties a node to its worker (bwrap's --die-with-parent does when
    # sandboxed): the web process ends the dead worker's process group.
    server = start_server(tmp_path, {"ROBODOJO_WORKERS": "1", "ROBODOJO_UNSAFE_NO_SANDBOX": "1"})
    try:
        kill_a_worker_mid_run_and_expect_no_orphans(server)
    finally:
        stop_server(server)


def kill_a_worker_mid_run_and_expect_no_orphans(lab: LabServer) -> None:
    student = lab.student("orphans")
    run_id = start_crowbot_run(student, clock="realtime", duration_s=120.0)
    wait_until(
        lambda: student.get(f"/api/runs/{run_id}").json()["state"] == "running", 60, "running"
    )
    worker = worker_of(lab, run_id)
    assert worker is not None
    worker_pid = int(worker.rsplit(":", 1)[1])
    # The run's node (bwrap and the Python inside it) and the warm ones waiting for a run.
    sandboxes = wait_until(lambda: descendants(worker_pid), 30, "the worker's sandboxes")
    os.kill(worker_pid, signal.SIGKILL)
    wait_until(
        lambda: not [key for key in sandboxes if process_alive(key)],
        ORPHANS_GONE_WITHIN_S,
        f"every sandbox process of the killed worker ended: {sandboxes}",
    )
    assert wait_for_end(student, run_id)["state"] == "failed"


@pytest.mark.slow
def test_a_server_stopping_stops_its_workers_runs_cleanly(tmp_path):
    server = start_server(tmp_path, {"ROBODOJO_WORKERS": str(WORKERS)})
    try:
        student = server.student("leaving")
        run_id = start_crowbot_run(student, clock="realtime", duration_s=120.0)
        wait_until(
            lambda: student.get(f"/api/runs/{run_id}").json()["state"] == "running", 60, "running"
        )
        worker = worker_of(server, run_id)
    finally:
        # uvicorn ends by raising the SIGTERM it handled, after the application's shutdown.
        assert stop_server(server) in (0, -signal.SIGTERM)
    assert worker is not None
    wait_until(lambda: not pid_alive(int(worker.rsplit(":", 1)[1])), 10, "the worker ended")
    store = Store.open(server.database_url)
    try:
        with store.session() as db:
            record = run_store.get(db, run_id)
            assert record.state == "interrupted", record.reason
            assert "shutting down" in record.reason  # stopped by its worker, not found cut off
    finally:
        store.close()


@pytest.mark.slow
def test_a_service_managers_stop_of_the_whole_group_ends_runs_quietly(tmp_path):
    # systemd (KillMode=control-group), `docker stop` of a shell and Ctrl-C signal every
    # process of the lab at once: the web process, its worker processes and the forkserver
    # that made them. The workers' runs end "shutting down", and nothing is said to be lost.
    env = {"ROBODOJO_WORKERS": str(WORKERS), "ROBODOJO_EDITOR_WORKERS": "0"}  # none starting
    server = start_server(tmp_path, env, own_session=True)
    try:
        student = server.student("group-stop")
        run_id = start_crowbot_run(student, clock="realtime", duration_s=120.0)
        wait_until(
            lambda: student.get(f"/api/runs/{run_id}").json()["state"] == "running", 60, "running"
        )
        signalled_at = len(server.output)  # what it said from here on
        os.killpg(server.process.pid, signal.SIGTERM)
        server.process.wait(60)
    finally:
        stop_server(server)
    alarming = [
        line
        for line in server.output[signalled_at:]
        if "exit code" in line or line.startswith(("ERROR", "WARNING", "Traceback"))
    ]
    assert not alarming, "\n".join(server.output[-60:])
    store = Store.open(server.database_url)
    try:
        with store.session() as db:
            record = run_store.get(db, run_id)
            assert record.state == "interrupted" and "shutting down" in record.reason, record.reason
    finally:
        store.close()


def pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    return True


def _stat(pid: int) -> list[str] | None:
    """/proc/PID/stat's fields after the command name (state first), or None if it is gone."""
    try:
        with open(f"/proc/{pid}/stat") as f:
            text = f.read()
    except OSError:
        return None
    return text[text.rindex(")") + 2 :].split()


def descendants(pid: int) -> dict[tuple[int, str], str]:
    """Every live process below `pid`: (pid, start time) -> its command name. The start time
    tells a reused pid from the process seen."""
    children: dict[int, list[int]] = {}
    names: dict[int, str] = {}
    starts: dict[int, str] = {}
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        fields = _stat(int(entry))
        if fields is None:
            continue
        children.setdefault(int(fields[1]), []).append(int(entry))
        starts[int(entry)] = fields[19]
        try:
            with open(f"/proc/{entry}/comm") as f:
                names[int(entry)] = f.read().strip()
        except OSError:
            names[int(entry)] = "?"
    found: dict[tuple[int, str], str] = {}
    stack = list(children.get(pid, []))
    while stack:
        child = stack.pop()
        found[(child, starts[child])] = names[child]
        stack.extend(children.get(child, []))
    return found


def process_alive(key: tuple[int, str]) -> bool:
    """Whether the process (pid, start time) still runs (a zombie has ended)."""
    fields = _stat(key[0])
    return fields is not None and fields[19] == key[1] and fields[0] != "Z"
