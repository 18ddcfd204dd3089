"""One thread listening to a changing set of Redis pub/sub channels, which outlives Redis
restarts: the worker's command channels of the runs it holds, a web process's live channels of
the runs someone watches there (issue 16).

redis-py's PubSub is one connection read by one thread, so the set of channels is changed by
that thread too: callers say what they want (`add`, `remove`) and the thread subscribes between
two reads. When the connection breaks it reconnects with a back-off, subscribes to everything
wanted again and calls `on_connect` (a web process reads again what it missed).

    listener = ChannelListener(client, handle=lambda channel, data: ..., name="commands")
    listener.start()
    listener.add("robodojo:cmd:<run_id>", wait_s=1.0)    # True once Redis confirmed it
    listener.remove("robodojo:cmd:<run_id>")
"""

from __future__ import annotations

import contextlib
import logging
import threading
from collections.abc import Callable

import redis

log = logging.getLogger("robodojo.workers.channels")

POLL_S = 0.02  # [s] longest wait for a message before the thread looks at added channels
RECONNECT_FIRST_S = 0.2  # [s] first wait after the connection broke
RECONNECT_MAX_S = 2.0  # [s] longest wait between two tries: back within ~2 s of Redis


class ChannelListener:
    """Calls `handle(channel, data)` on its own thread for every message on the wanted
    channels; `on_subscribed(channel)` when Redis confirmed a subscription (also after a
    reconnect); `on_connect()` after every reconnect. A callback's exception is logged and the
    listener goes on."""

    def __init__(
        self,
        client: redis.Redis,
        handle: Callable[[str, bytes], None],
        name: str,
        on_subscribed: Callable[[str], None] | None = None,
        on_connect: Callable[[], None] | None = None,
    ) -> None:
        self.client = client
        self.handle = handle
        self.on_subscribed = on_subscribed
        self.on_connect = on_connect
        self.name = name
        self.connected = False
        self._wanted: set[str] = set()
        self._confirmed: set[str] = set()
        # Waiters of `add`, told when Redis confirms their channel: a flag of their own, since
        # `_confirmed` can lose the channel again before a waiter looks (a catch-up that finds
        # the run over removes it at once).
        self._waiters: dict[str, list[threading.Event]] = {}
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._loop, name=f"redis-{name}", daemon=True)

    def start(self) -> None:
        self._thread.start()

    def stop(self) -> None:
        self._stop.set()
        self._thread.join(timeout=5)

    def add(self, channel: str, wait_s: float = 0.0) -> bool:
        """Listen to `channel`; with `wait_s`, wait that long for Redis to confirm (True)."""
        confirmed = threading.Event()
        with self._lock:
            self._wanted.add(channel)
            if channel in self._confirmed or wait_s <= 0:
                return channel in self._confirmed
            self._waiters.setdefault(channel, []).append(confirmed)
        try:
            return confirmed.wait(wait_s)
        finally:
            with self._lock:
                waiters = self._waiters.get(channel, [])
                if confirmed in waiters:
                    waiters.remove(confirmed)
                if not waiters:
                    self._waiters.pop(channel, None)

    def remove(self, channel: str) -> None:
        with self._lock:
            self._wanted.discard(channel)

    def wanted(self) -> set[str]:
        with self._lock:
            return set(self._wanted)

    # ------------------------------------------------------------------------------ thread
    def _loop(self) -> None:
        delay = RECONNECT_FIRST_S
        while not self._stop.is_set():
            pubsub = self.client.pubsub()
            try:
                self._listen(pubsub)
            except Exception as error:  # this thread must outlive anything
                if isinstance(error, redis.RedisError | OSError):
                    if self.connected:
                        log.warning("%s: lost Redis (%s); reconnecting", self.name, error)
                else:  # a fault of the client library or ours: said in full, then go on
                    log.exception("%s: the listener failed; starting it again", self.name)
                self.connected = False
                with self._lock:
                    self._confirmed.clear()
                self._stop.wait(delay)
                delay = min(delay * 2, RECONNECT_MAX_S)
            else:
                delay = RECONNECT_FIRST_S
            finally:
                with contextlib.suppress(Exception):  # a broken connection: nothing to close
                    pubsub.close()

    def _listen(self, pubsub: redis.client.PubSub) -> None:
        subscribed: set[str] = set()
        self.client.ping()  # a dead Redis is an error here, not a silent wait
        if not self.connected:
            self.connected = True
            log.info("%s: connected to Redis", self.name)
            self._call(self.on_connect)
        while not self._stop.is_set():
            wanted = self.wanted()
            if wanted - subscribed:
                pubsub.subscribe(*(wanted - subscribed))
            if subscribed - wanted:
                pubsub.unsubscribe(*(subscribed - wanted))
                with self._lock:
                    self._confirmed -= subscribed - wanted
            subscribed = wanted
            message = pubsub.get_message(timeout=POLL_S)
            while message is not None:
                self._dispatch(message)
                message = pubsub.get_message(timeout=0)

    def _dispatch(self, message: dict) -> None:
        kind = message.get("type")
        channel = message.get("channel")
        channel = channel.decode() if isinstance(channel, bytes) else str(channel)
        if kind == "subscribe":
            self._call(self.on_subscribed, channel)  # first: a waiter finds its work done
            with self._lock:
                if channel in self._wanted:  # not removed meanwhile (by the callback, say)
                    self._confirmed.add(channel)
                for waiter in self._waiters.pop(channel, []):
                    waiter.set()
        elif kind == "message":
            self._call(self.handle, channel, message.get("data"))

    def _call(self, callback, *args) -> None:
        if callback is None:
            return
        try:
            callback(*args)
        except Exception:
            log.exception("%s: a callback failed", self.name)
