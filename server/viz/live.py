"""A live run followed in its view: the run's telemetry (server/service/telemetry.py) is the only
source, read through an ordinary `Viewer` like a browser's websocket, so the view never touches
the run's thread or its simulation. Latest value wins twice over: the viewer hands out each
topic's newest sample at most SUBSCRIBE_HZ, and frames are drawn at most DRAW_HZ with whatever
state has been folded in by then.

The lights are the one thing telemetry does not carry: `lights()` reads them (the manager binds
it to `RunService.lights` for this run; None once the run has ended).
"""

from __future__ import annotations

import asyncio
import logging
import time
from collections.abc import Callable

from server.service.telemetry import RunTelemetry
from server.sim.world import LightSource
from server.viz.view import SceneView
from server.viz.view_state import ViewState

log = logging.getLogger("robodojo.viz")
DRAW_HZ = 30.0  # [Hz] frames drawn per second at most
# [Hz] per topic, the telemetry's most: a cap at /tf's own 30 Hz would alias (a sample a little
# early waits for the next one) and halve the frames; DRAW_HZ does the thinning.
SUBSCRIBE_HZ = 60.0
IDLE_WAIT_S = 1.0  # [s] with nothing new, wake this often to notice a stop
SKIPPED_TOPICS = frozenset({"map"})  # the occupancy grid is drawn from the world, once


async def follow_live(
    view: SceneView,
    telemetry: RunTelemetry,
    lights: Callable[[], tuple[LightSource, ...] | None] = lambda: None,
    run_state: Callable[[], str | None] = lambda: None,
) -> ViewState:
    """Draw the run until its telemetry ends (returns the last state) or the task is cancelled.
    `lights()`: where the run's lights are now (None: unknown, the last ones drawn stay);
    `run_state()`: the run's state for the panel ("running", "paused"; None: say "live")."""
    viewer = telemetry.viewer()
    state = ViewState(lights=view.world.lights)
    subscribed: set[str] = set()

    def subscribe(topic: str) -> None:
        if topic not in subscribed and topic not in SKIPPED_TOPICS:
            subscribed.add(topic)
            viewer.subscribe(topic, SUBSCRIBE_HZ)

    for topic in telemetry.snapshot()["topics"]:
        subscribe(topic)
    period_s = 1.0 / DRAW_HZ
    next_draw_s = 0.0
    drawn_version = -1
    try:
        while not viewer.finished:
            dirty = state.version != drawn_version
            wait_s = max(0.0, next_draw_s - time.monotonic()) if dirty else IDLE_WAIT_S
            for frame in await viewer.next_frames(wait_s):
                kind = frame.get("type")
                if kind == "telemetry" and frame.get("msg") is not None:
                    state.apply(frame["topic"], frame["msg_type"], frame["time_s"], frame["msg"])
                elif kind == "topic":
                    subscribe(frame["topic"])
            now_lights = lights()
            if now_lights is not None and now_lights != state.lights:
                state.lights = now_lights
                state.version += 1
            now_s = time.monotonic()
            if state.version != drawn_version and now_s >= next_draw_s:
                drawn_version = state.version
                next_draw_s = now_s + period_s
                # Viser serializes on its own loop; the calls that queue it still cost ~1 ms a
                # frame, kept off the web server's loop. This task waits, so state holds still.
                await asyncio.to_thread(_draw, view, state, run_state())
        if state.version != drawn_version:  # the last frames came with the end
            await asyncio.to_thread(_draw, view, state, run_state())
    finally:
        viewer.close()
    return state


def _draw(view: SceneView, state: ViewState, run_state: str | None) -> None:
    try:
        view.draw(state)
        view.set_status(f"**{run_state or 'live'}** · t = {state.time_s:.2f} s")
    except Exception:  # a frame that cannot be drawn is skipped, the next one tried
        log.exception("live view: a frame failed to draw")
