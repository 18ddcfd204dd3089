"""A fault-injecting TCP relay: the lossy, jittery part of an emulated classroom WiFi link (test
tooling; this machine's kernel has no netem qdisc, so delay, jitter and loss are made here).

    python -m tests.hardware.wifi_relay 127.0.0.1 11411 10.213.0.1 40111 \\
        --delay 0.02 --jitter 0.01 --loss 0.02 --seed 7

The robot connects to the listening address; each connection is relayed to the target (the
server). Every chunk read in either direction is released after `delay` +- `jitter` [s], never
before the chunk ahead of it (TCP delivers in order). Loss on TCP is not a missing byte but a
late one: a lost segment is sent again after the retransmission timeout, and everything behind it
waits (head-of-line blocking). So a chunk "lost" with probability `loss` is released
`RETRANSMIT_S` later, and the chunks behind it queue up behind it.

Standard output: one JSON line per event ("ready", "connected", "stall" with the direction and
its extra delay, "closed"). Standard input: a line "drop" closes the connections open now (a WiFi
reassociation: the robot sees its socket close and reconnects).
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import random
import socket
import sys
import threading
import time
from collections import deque

RETRANSMIT_S = 0.2  # [s] Linux's minimum TCP retransmission timeout (TCP_RTO_MIN)
CHUNK_BYTES = 1460  # [bytes] one Ethernet-sized segment at a time, as a link carries them


def report(**event: object) -> None:
    print(json.dumps({"t": time.monotonic(), **event}), flush=True)


class Direction:
    """One direction of one connection: read, delay, write in order."""

    def __init__(
        self, name: str, source: socket.socket, sink: socket.socket, options, rng: random.Random
    ) -> None:
        self.name, self.source, self.sink = name, source, sink
        self.options, self.rng = options, rng
        self.pending: deque[tuple[float, bytes]] = deque()
        self.ready = threading.Condition()
        self.closed = False
        self.last_release_s = 0.0

    def read(self) -> None:
        options = self.options
        while True:
            try:
                data = self.source.recv(CHUNK_BYTES)
            except OSError:
                data = b""
            now = time.monotonic()
            with self.ready:
                if not data:
                    self.closed = True
                    self.ready.notify()
                    return
                delay = max(0.0, options.delay + self.rng.uniform(-options.jitter, options.jitter))
                if self.rng.random() < options.loss:
                    delay += RETRANSMIT_S
                    report(event="stall", dir=self.name, stall_s=RETRANSMIT_S)
                release = max(self.last_release_s, now + delay)
                self.last_release_s = release
                self.pending.append((release, data))
                self.ready.notify()

    def write(self) -> None:
        while True:
            with self.ready:
                while not self.pending and not self.closed:
                    self.ready.wait()
                if not self.pending:
                    break
                release, data = self.pending[0]
            wait = release - time.monotonic()
            if wait > 0:
                time.sleep(wait)
            with self.ready:
                self.pending.popleft()
            try:
                self.sink.sendall(data)
            except OSError:
                break
        with contextlib.suppress(OSError):
            self.sink.shutdown(socket.SHUT_WR)


class Relay:
    def __init__(self, options) -> None:
        self.options = options
        self.rng = random.Random(options.seed)
        self.connections: list[tuple[socket.socket, socket.socket]] = []
        self.lock = threading.Lock()

    def serve(self) -> None:
        listener = socket.create_server((self.options.listen_host, self.options.listen_port))
        threading.Thread(target=self.commands, daemon=True).start()
        report(event="ready")
        while True:
            robot, _ = listener.accept()
            try:
                server = socket.create_connection(
                    (self.options.target_host, self.options.target_port), timeout=5.0
                )
            except OSError as error:
                report(event="refused", error=str(error))
                robot.close()
                continue
            server.settimeout(None)
            for sock in (robot, server):
                sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            with self.lock:
                self.connections.append((robot, server))
            report(event="connected")
            for direction in (
                Direction("up", robot, server, self.options, self.rng),
                Direction("down", server, robot, self.options, self.rng),
            ):
                threading.Thread(target=direction.read, daemon=True).start()
                threading.Thread(target=direction.write, daemon=True).start()

    def commands(self) -> None:
        for line in sys.stdin:
            if line.strip() == "drop":
                with self.lock:
                    dropped, self.connections = self.connections, []
                for pair in dropped:
                    for sock in pair:
                        with contextlib.suppress(OSError):
                            sock.shutdown(socket.SHUT_RDWR)
                        sock.close()
                report(event="closed", count=len(dropped))
        os._exit(0)  # stdin closed: the test is over (the accept loop ends with us)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("listen_host")
    parser.add_argument("listen_port", type=int)
    parser.add_argument("target_host")
    parser.add_argument("target_port", type=int)
    parser.add_argument("--delay", type=float, default=0.02, help="[s] one way")
    parser.add_argument("--jitter", type=float, default=0.01, help="[s] +- around the delay")
    parser.add_argument("--loss", type=float, default=0.02, help="chance a chunk is retransmitted")
    parser.add_argument("--seed", type=int, default=0)
    options = parser.parse_args()
    with contextlib.suppress(KeyboardInterrupt):
        Relay(options).serve()


if __name__ == "__main__":
    main()
