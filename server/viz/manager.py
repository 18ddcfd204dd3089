"""One ViserServer per watched run, on a free loopback port, started when someone opens the run's
view and stopped once nobody has watched it for IDLE_STOP_S.

    manager = VizManager(run_service)                 # in the app's lifespan (LiveRuns)
    session = await manager.open(run_id, robot, world, run_dir)   # the page or its websocket
    async with manager.watching(session): ...         # while a proxied websocket is open
    await manager.close()                             # at shutdown: every server stopped

A session shows an active run live (live.py) and, when it ends, replays its recording in the same
scene (replay.py); a run that ended before anyone looked is replayed from the start; one without
a recording shows its world and says so. The live run is reached only through the run service
(`LiveRuns`): its telemetry to draw, its lights, and typed commands for the view's clicks.

The viser port answers anyone on this machine without asking who they are (viser has no auth):
it is bound to 127.0.0.1 only, and the API's proxy (server/api/routes/viz.py) is the door.
"""

from __future__ import annotations

import asyncio
import contextlib
import functools
import logging
import threading
import time
from collections.abc import AsyncIterator
from dataclasses import dataclass, field
from enum import StrEnum
from pathlib import Path
from typing import Protocol

from server.runs.commands import RunCommand
from server.runs.recorder import RECORDING_FILE
from server.service.telemetry import RunTelemetry
from server.sim.world import LightSource
from server.viz.live import follow_live
from server.viz.recording import RecordingError, load_recording
from server.viz.replay import ReplayPlayer
from server.viz.view import SceneView

log = logging.getLogger("robodojo.viz")
IDLE_STOP_S = 60.0  # [s] a view nobody has watched this long is stopped (its port freed)
REAP_PERIOD_S = 5.0  # [s] how often idle views are looked for
END_WAIT_S = 120.0  # [s] after a live run's telemetry ends, wait this long for its recording
END_POLL_S = 0.1  # [s]
LOOPBACK = "127.0.0.1"


class LiveRuns(Protocol):
    """What the views need of the run service (server/service/runs.py RunService)."""

    def feed(self, run_id: str) -> RunTelemetry | None: ...

    def is_running(self, run_id: str) -> bool: ...

    def lights(self, run_id: str) -> tuple[LightSource, ...] | None: ...

    def live(self, run_id: str) -> RunSnapshot | None: ...

    def command(self, run_id: str, command: RunCommand) -> bool: ...


class RunSnapshot(Protocol):
    """The part of RunService.live()'s LiveRun the panel shows."""

    @property
    def state(self) -> object: ...


class Mode(StrEnum):
    LIVE = "live"
    REPLAY = "replay"
    NO_RECORDING = "no_recording"


@dataclass
class VizSession:
    run_id: str
    server: object  # viser.ViserServer
    view: SceneView
    run_dir: Path
    mode: Mode
    last_seen_s: float = field(default_factory=time.monotonic)  # [s] monotonic
    watchers: int = 0
    feed: asyncio.Task | None = None
    player: ReplayPlayer | None = None
    stopped: bool = False
    # Held while the replay is set up and while stopping, so a server is never stopped halfway
    # through building its replay (the live feed's end and an idle stop can meet).
    lock: threading.Lock = field(default_factory=threading.Lock)

    @property
    def port(self) -> int:
        return self.server.get_port()

    def start_replay(self) -> None:
        """Replay the recording in this scene (blocking: loads the file)."""
        with self.lock:
            if self.stopped:
                return
            try:
                recording = load_recording(self.run_dir / RECORDING_FILE)
            except RecordingError as error:
                self.mode = Mode.NO_RECORDING
                self.view.set_status(f"**no replay**: {error}")
                return
            self.player = ReplayPlayer(self.server, self.view, recording)
            self.mode = Mode.REPLAY

    def stop(self) -> None:
        """Blocking: joins the player and viser's threads."""
        with self.lock:
            self.stopped = True
            if self.player is not None:
                self.player.close()
            self.server.stop()


def _quiet_viser() -> None:
    """Viser prints a banner and connection lines to stdout through rich for every server;
    nothing else here uses rich, so its console is silenced once (the manager logs instead)."""
    import rich

    rich.get_console().quiet = True


class VizManager:
    def __init__(
        self,
        runs: LiveRuns | None = None,
        idle_stop_s: float = IDLE_STOP_S,
        reap_period_s: float = REAP_PERIOD_S,
    ) -> None:
        """`runs`: the RunService whose active runs are shown live (None: replays only)."""
        self.runs = runs
        self.idle_stop_s = idle_stop_s
        self.reap_period_s = reap_period_s
        self.sessions: dict[str, VizSession] = {}
        self._opening: dict[str, asyncio.Lock] = {}
        self._reaper: asyncio.Task | None = None
        self._closed = False
        _quiet_viser()

    # ----------------------------------------------------------------------------- opening
    async def open(self, run_id: str, robot: str, world: str, run_dir: str | Path) -> VizSession:
        """The run's session, started if it has none; counts as a look (resets the idle time)."""
        if self._closed:
            raise RuntimeError("the 3D views are shutting down")
        self._start_reaper()
        lock = self._opening.setdefault(run_id, asyncio.Lock())
        async with lock:
            session = self.sessions.get(run_id)
            if session is None:
                telemetry = self.runs.feed(run_id) if self.runs is not None else None
                session = await asyncio.to_thread(
                    self._create, run_id, robot, world, Path(run_dir), telemetry is not None
                )
                self.sessions[run_id] = session
                if telemetry is not None:
                    session.feed = asyncio.create_task(self._follow(session, telemetry))
                log.info(
                    "run %s: 3D view (%s) on %s:%d", run_id, session.mode, LOOPBACK, session.port
                )
        session.last_seen_s = time.monotonic()
        return session

    def _create(self, run_id: str, robot: str, world: str, run_dir: Path, live: bool) -> VizSession:
        import viser

        server = viser.ViserServer(host=LOOPBACK, port=0, label=f"run {run_id[:12]}", verbose=False)
        try:
            send = functools.partial(self.runs.command, run_id) if live else None
            view = SceneView(server, robot, world, send)
            session = VizSession(run_id, server, view, run_dir, Mode.LIVE if live else Mode.REPLAY)
            if not live:
                session.start_replay()
            return session
        except BaseException:
            server.stop()
            raise

    async def _follow(self, session: VizSession, telemetry: RunTelemetry) -> None:
        """Live until the run's telemetry ends, then (recording closed) replay."""
        lights = functools.partial(self.runs.lights, session.run_id)
        runs, run_id = self.runs, session.run_id

        def run_state() -> str | None:
            live = runs.live(run_id)
            return None if live is None else str(live.state)

        try:
            await follow_live(session.view, telemetry, lights, run_state)
        except asyncio.CancelledError:
            raise
        except Exception:
            log.exception("run %s: the live 3D view failed", session.run_id)
        session.view.stop_controls()
        session.view.set_status("**ended**: loading the replay…")
        deadline = time.monotonic() + END_WAIT_S
        while self.runs.is_running(session.run_id) and time.monotonic() < deadline:
            await asyncio.sleep(END_POLL_S)
        await asyncio.to_thread(session.start_replay)

    # ----------------------------------------------------------------------------- watching
    @contextlib.asynccontextmanager
    async def watching(self, session: VizSession) -> AsyncIterator[None]:
        """Held while a proxied websocket is open: the session is not idle meanwhile."""
        session.watchers += 1
        session.last_seen_s = time.monotonic()
        try:
            yield
        finally:
            session.watchers -= 1
            session.last_seen_s = time.monotonic()

    # ----------------------------------------------------------------------------- stopping
    def _start_reaper(self) -> None:
        if self._reaper is None or self._reaper.done():
            self._reaper = asyncio.create_task(self._reap_forever())

    async def _reap_forever(self) -> None:
        while True:
            await asyncio.sleep(self.reap_period_s)
            try:
                await self.reap()
            except Exception:
                log.exception("stopping idle 3D views failed")

    async def reap(self, now_s: float | None = None) -> list[str]:
        """Stop every session nobody watches and nobody has looked at for idle_stop_s."""
        now_s = time.monotonic() if now_s is None else now_s
        idle = [
            run_id
            for run_id, session in self.sessions.items()
            if session.watchers == 0 and now_s - session.last_seen_s >= self.idle_stop_s
        ]
        for run_id in idle:
            await self.stop(run_id)
        return idle

    async def stop(self, run_id: str, why: str = "idle") -> bool:
        session = self.sessions.pop(run_id, None)
        self._opening.pop(run_id, None)
        if session is None:
            return False
        if session.feed is not None:
            session.feed.cancel()
            with contextlib.suppress(BaseException):
                await session.feed
        await asyncio.to_thread(session.stop)
        log.info("run %s: 3D view stopped (%s)", run_id, why)
        return True

    async def close(self) -> None:
        self._closed = True
        if self._reaper is not None:
            self._reaper.cancel()
            with contextlib.suppress(BaseException):
                await self._reaper
        for run_id in list(self.sessions):
            await self.stop(run_id, "shutting down")
