"""The view manager: a viser server started on demand on a free loopback port, the same one for
every look, stopped (its port freed) once nobody has watched for the idle time; a live run's
view turns into its replay when the run ends."""

from __future__ import annotations

import asyncio
import http.client
import socket
import threading
import time
from types import SimpleNamespace

import pytest

from server.runs.commands import Goal, RunCommand
from server.runs.run import Run
from server.service.telemetry import RunTelemetry
from server.viz.manager import LOOPBACK, Mode, VizManager
from tests.viz.conftest import crowbot_spec


def page_status(port: int) -> int:
    connection = http.client.HTTPConnection(LOOPBACK, port, timeout=5)
    try:
        connection.request("GET", "/")
        answer = connection.getresponse()
        assert b"<html" in answer.read(200).lower()
        return answer.status
    finally:
        connection.close()


def port_is_free(port: int) -> bool:
    with socket.socket() as sock:
        try:
            sock.bind((LOOPBACK, port))
        except OSError:
            return False
    return True


class FakeService:
    """RunService's door for the views (manager.LiveRuns), for the runs a test says are going."""

    def __init__(self) -> None:
        self.running: dict[str, SimpleNamespace] = {}
        self.sent: list[tuple[str, RunCommand]] = []

    def feed(self, run_id: str):
        active = self.running.get(run_id)
        return active.telemetry if active is not None else None

    def is_running(self, run_id: str) -> bool:
        return run_id in self.running

    def lights(self, run_id: str):
        active = self.running.get(run_id)
        return active.run.sim.lights if active is not None and active.run.sim else None

    def live(self, run_id: str):
        active = self.running.get(run_id)
        return SimpleNamespace(state=active.run.state) if active is not None else None

    def command(self, run_id: str, command: RunCommand) -> bool:
        self.sent.append((run_id, command))
        return run_id in self.running


def test_a_view_starts_on_demand_is_shared_and_stops_when_idle(crowbot_run):
    async def main() -> None:
        manager = VizManager(idle_stop_s=60.0)
        first = await manager.open("r1", "crowbot", "light_arena", crowbot_run)
        assert first.mode is Mode.REPLAY and first.server.get_host() == LOOPBACK
        assert page_status(first.port) == 200
        assert await manager.open("r1", "crowbot", "light_arena", crowbot_run) is first
        port = first.port
        assert not port_is_free(port)
        assert await manager.reap(time.monotonic() + 30.0) == []  # looked at recently
        async with manager.watching(first):
            assert first.watchers == 1
            assert await manager.reap(time.monotonic() + 3600.0) == []  # someone is watching
        assert await manager.reap(time.monotonic() + 61.0) == ["r1"]
        assert manager.sessions == {}
        assert port_is_free(port)
        again = await manager.open("r1", "crowbot", "light_arena", crowbot_run)
        assert again is not first and page_status(again.port) == 200
        await manager.close()
        assert port_is_free(again.port)

    asyncio.run(main())


def test_two_runs_get_two_servers_and_concurrent_opens_make_one(crowbot_run, turtlebot_run):
    async def main() -> None:
        manager = VizManager()
        a, b, a_again = await asyncio.gather(
            manager.open("a", "crowbot", "light_arena", crowbot_run),
            manager.open("b", "turtlebot", "office", turtlebot_run),
            manager.open("a", "crowbot", "light_arena", crowbot_run),
        )
        assert a is a_again and a.port != b.port and len(manager.sessions) == 2
        await manager.close()
        with pytest.raises(RuntimeError, match="shutting down"):
            await manager.open("c", "crowbot", "light_arena", crowbot_run)

    asyncio.run(main())


def test_the_reaper_stops_idle_views_by_itself(crowbot_run):
    async def main() -> None:
        manager = VizManager(idle_stop_s=0.2, reap_period_s=0.05)
        session = await manager.open("r", "crowbot", "light_arena", crowbot_run)
        deadline = time.monotonic() + 5.0
        while manager.sessions and time.monotonic() < deadline:
            await asyncio.sleep(0.05)
        assert manager.sessions == {} and port_is_free(session.port)
        await manager.close()

    asyncio.run(main())


def test_a_run_without_recording_shows_its_world_and_says_so(tmp_path):
    async def main() -> None:
        manager = VizManager()
        session = await manager.open("none", "turtlebot", "office", tmp_path)
        assert session.mode is Mode.NO_RECORDING
        assert "no recording" in session.view.status.content
        assert session.server.scene.get_handle_by_name("/world/map") is not None
        await manager.close()

    asyncio.run(main())


def test_a_live_view_becomes_the_replay_when_the_run_ends(launcher, tmp_path):
    service = FakeService()
    telemetry = RunTelemetry("live")
    run = Run(crowbot_spec(duration_s=1.0), launcher, tmp_path, observer=telemetry)
    service.running["live"] = SimpleNamespace(run=run, telemetry=telemetry)

    def execute() -> None:
        run.execute()
        del service.running["live"]  # as RunService does once the run is stored

    async def main() -> None:
        manager = VizManager(service)
        session = await manager.open("live", "crowbot", "light_arena", tmp_path)
        assert session.mode is Mode.LIVE and session.view.send is not None
        session.view.send(Goal(0.5, 0.5))  # the view's clicks go to the service, typed
        assert service.sent == [("live", Goal(0.5, 0.5))]
        worker = threading.Thread(target=execute)
        worker.start()
        await asyncio.wait_for(session.feed, timeout=30.0)
        worker.join()
        assert session.mode is Mode.REPLAY and session.player is not None
        assert session.view.send is None  # an ended run takes no clicks
        await manager.close()

    asyncio.run(main())
