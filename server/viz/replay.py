"""Replay of a finished run in its scene: a time slider, play/pause and a speed choice in viser's
GUI panel, and one player thread that draws the newest time asked for (a slider dragged fast
asks for many; only the last is drawn, latest wins).

    player = ReplayPlayer(server, view, recording)   # draws t = 0 at once
    player.close()                                    # joins the thread
"""

from __future__ import annotations

import logging
import threading
import time

from server.viz.recording import Recording
from server.viz.view import SceneView

log = logging.getLogger("robodojo.viz")
PLAYBACK_HZ = 30.0  # [Hz] frames drawn per second while playing
SLIDER_STEP_S = 0.01  # [s] the slider's resolution
SPEEDS = ("0.25x", "0.5x", "1x", "2x", "4x", "8x")


class ReplayPlayer:
    def __init__(self, server, view: SceneView, recording: Recording) -> None:
        self.view = view
        self.recording = recording
        self.duration_s = max(recording.duration_s, SLIDER_STEP_S)
        gui = server.gui
        self.slider = gui.add_slider(
            "time [s]", min=0.0, max=self.duration_s, step=SLIDER_STEP_S, initial_value=0.0
        )
        self.play_button = gui.add_button("Play", icon="player-play")
        self.speed = gui.add_dropdown("speed", SPEEDS, initial_value="1x")
        self.playing = False
        self._wanted_s = 0.0
        self._shown_s: float | None = None
        self._wake = threading.Event()
        self._closed = threading.Event()
        self.slider.on_update(self._slid)
        self.play_button.on_click(self._toggle)
        self.lights = view.world.lights
        self._thread = threading.Thread(target=self._loop, name="viz-replay", daemon=True)
        self._thread.start()
        self._wake.set()

    # ----------------------------------------------------------------------------- GUI events
    def _slid(self, event) -> None:
        if event.client is None:  # our own update while playing
            return
        self._wanted_s = float(self.slider.value)
        self._wake.set()

    def _toggle(self, _event) -> None:
        self.set_playing(not self.playing)

    def set_playing(self, playing: bool) -> None:
        if playing and self._wanted_s >= self.duration_s:
            self._wanted_s = 0.0  # play again from the start
        self.playing = playing
        self.play_button.label = "Pause" if playing else "Play"
        self.play_button.icon = "player-pause" if playing else "player-play"
        self._wake.set()

    def seek(self, time_s: float) -> None:
        self._wanted_s = min(max(float(time_s), 0.0), self.duration_s)
        self._wake.set()

    # ----------------------------------------------------------------------------- drawing
    def _loop(self) -> None:
        period_s = 1.0 / PLAYBACK_HZ
        last = time.monotonic()
        while not self._closed.is_set():
            self._wake.wait(period_s if self.playing else 1.0)
            self._wake.clear()
            now = time.monotonic()
            if self.playing:
                speed = float(self.speed.value.rstrip("x"))
                self._wanted_s = min(self._wanted_s + (now - last) * speed, self.duration_s)
                self.slider.value = round(self._wanted_s / SLIDER_STEP_S) * SLIDER_STEP_S
                if self._wanted_s >= self.duration_s:
                    self.set_playing(False)
            last = now
            wanted = self._wanted_s
            if wanted == self._shown_s:
                continue
            try:
                self.view.draw(self.recording.state_at(wanted, self.lights))
                self.view.set_status(
                    f"**replay** · ended · t = {wanted:.2f} s of {self.duration_s:.2f} s"
                )
            except Exception:  # one bad frame must not end the replay
                log.exception("replay of %s: frame at %.3f s failed", self.recording.path, wanted)
            self._shown_s = wanted

    @property
    def shown_s(self) -> float | None:
        return self._shown_s

    def close(self) -> None:
        self._closed.set()
        self._wake.set()
        self._thread.join(timeout=5.0)
