"""An emulated classroom WiFi link between the server and a robot, made by a test and torn down
after it: the robot (the firmware emulator) lives in its own network namespace, joined to the
host by a veth pair; the kernel gives the link its rate (tc tbf) and its drops (ip link set
down), a relay inside the namespace gives it delay, jitter and loss (tests/hardware/wifi_relay.py;
this kernel has no netem qdisc), and SIGSTOP freezes the robot (tests/hardware/robot_process.py).

    host (server, rosserial on all interfaces)          namespace rd-wifi-<pid>
      veth 10.W.X.1/30  <--- tbf 2 Mbit --->  veth 10.W.X.2/30 (the robot's address)
                                                relay 127.0.0.1:11411 -> 10.W.X.1:<rosserial>
                                                firmware -> 127.0.0.1:11411

The server sees the robot's own address (10.W.X.2), so admission works as on a bench.
"""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import subprocess
import sys
import threading
import time
from dataclasses import dataclass

from tests.hardware.robot_process import REPO

RELAY_PORT = 11411  # inside the namespace: the port ros_lib's ArduinoTcpHardware dials
LINK_RATE = "2mbit"  # a robot's share of a busy classroom access point
LINK_DELAY_S = 0.02  # [s] one way, WiFi with a few retries
LINK_JITTER_S = 0.01  # [s] +- around it
LINK_LOSS = 0.02  # 2 % of segments retransmitted (relay: RETRANSMIT_S later)


def namespaces_unavailable() -> str | None:
    """None when this machine can make a network namespace and a veth pair; else why not."""
    if shutil.which("ip") is None:
        return "the `ip` command (iproute2) is missing, so no network namespace can be made"
    if os.geteuid() != 0:
        return "network namespaces need root (CAP_NET_ADMIN); run as root to test over WiFi"
    probe = f"rd-probe-{os.getpid()}"
    made = subprocess.run(["ip", "netns", "add", probe], capture_output=True, text=True)
    if made.returncode != 0:
        return f"`ip netns add` failed here ({made.stderr.strip()}), so no emulated WiFi link"
    subprocess.run(["ip", "netns", "del", probe], capture_output=True)
    return None


def _ip(*args: str) -> None:
    subprocess.run(["ip", *args], check=True, capture_output=True, text=True)


@dataclass(frozen=True)
class Addresses:
    host: str  # the server's end of the veth
    robot: str  # the robot's address, as the server sees it


class EmulatedWifi:
    """See the module docstring. `start(rosserial_port)`, then run the robot with `prefix`."""

    def __init__(
        self,
        delay_s: float = LINK_DELAY_S,
        jitter_s: float = LINK_JITTER_S,
        loss: float = LINK_LOSS,
        seed: int = 17,
    ) -> None:
        pid = os.getpid()
        self.namespace = f"rd-wifi-{pid}"
        self.host_if, self.robot_if = f"rdw{pid % 100000}h", f"rdw{pid % 100000}r"
        subnet = pid % 16000
        base = f"10.{200 + subnet // 250 % 50}.{subnet % 250}"
        self.addresses = Addresses(f"{base}.1", f"{base}.2")
        self.delay_s, self.jitter_s, self.loss, self.seed = delay_s, jitter_s, loss, seed
        self.events: list[dict] = []
        self._relay: subprocess.Popen[str] | None = None
        self._lock = threading.Lock()

    @property
    def prefix(self) -> list[str]:
        """Put before a command to run it in the robot's namespace."""
        return ["ip", "netns", "exec", self.namespace]

    @property
    def worst_one_way_s(self) -> float:
        """[s] a segment's longest trip when it is not retransmitted."""
        return self.delay_s + self.jitter_s

    def start(self, rosserial_port: int) -> EmulatedWifi:
        ns, host_if, robot_if = self.namespace, self.host_if, self.robot_if
        _ip("netns", "add", ns)
        try:
            _ip("link", "add", host_if, "type", "veth", "peer", "name", robot_if)
            _ip("link", "set", robot_if, "netns", ns)
            _ip("addr", "add", f"{self.addresses.host}/30", "dev", host_if)
            _ip("link", "set", host_if, "up")
            _ip("-n", ns, "addr", "add", f"{self.addresses.robot}/30", "dev", robot_if)
            _ip("-n", ns, "link", "set", robot_if, "up")
            _ip("-n", ns, "link", "set", "lo", "up")
            for where, device in (([], host_if), (["ip", "netns", "exec", ns], robot_if)):
                subprocess.run(
                    [*where, "tc", "qdisc", "add", "dev", device, "root", "tbf", "rate",
                     LINK_RATE, "burst", "32kbit", "latency", "100ms"],
                    check=True, capture_output=True,
                )  # fmt: skip
            self._relay = subprocess.Popen(
                [*self.prefix, sys.executable, "-m", "tests.hardware.wifi_relay", "127.0.0.1",
                 str(RELAY_PORT), self.addresses.host, str(rosserial_port), "--delay",
                 str(self.delay_s), "--jitter", str(self.jitter_s), "--loss", str(self.loss),
                 "--seed", str(self.seed)],
                cwd=REPO, stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True,
            )  # fmt: skip
            threading.Thread(target=self._read_events, daemon=True).start()
            if not self.wait_for_event("ready", 10.0):
                raise RuntimeError("the WiFi relay did not start in the robot's namespace")
        except BaseException:
            self.stop()
            raise
        return self

    def _read_events(self) -> None:
        relay = self._relay
        assert relay is not None and relay.stdout is not None
        for line in relay.stdout:
            with self._lock:
                self.events.append(json.loads(line))

    def wait_for_event(self, name: str, timeout_s: float, after_s: float = 0.0) -> bool:
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            if self.events_named(name, after_s):
                return True
            time.sleep(0.01)
        return False

    def events_named(self, name: str, after_s: float = 0.0) -> list[dict]:
        with self._lock:
            return [e for e in self.events if e["event"] == name and e["t"] >= after_s]

    def stalls(self, direction: str, start_s: float, end_s: float) -> int:
        """Retransmissions the relay emulated in `direction` ("up", "down") in a window."""
        return sum(
            1 for e in self.events_named("stall") if e["dir"] == direction
            and start_s <= e["t"] <= end_s
        )  # fmt: skip

    def link_down(self) -> None:
        """The WiFi drops: the host's end of the veth goes down (segments are lost, TCP
        retransmits; the connection survives if the link comes back in time)."""
        _ip("link", "set", self.host_if, "down")

    def link_up(self) -> None:
        _ip("link", "set", self.host_if, "up")

    def reassociate(self) -> None:
        """The relay closes the robot's connection (the robot reconnects, as ros_lib does)."""
        relay = self._relay
        assert relay is not None and relay.stdin is not None
        relay.stdin.write("drop\n")
        relay.stdin.flush()

    def stop(self) -> None:
        relay = self._relay
        if relay is not None:
            with contextlib.suppress(OSError, ValueError):
                assert relay.stdin is not None
                relay.stdin.close()
            try:
                relay.wait(5.0)
            except subprocess.TimeoutExpired:
                relay.kill()
                relay.wait(5.0)
            if relay.stdout is not None:
                relay.stdout.close()
        # Deleting the namespace deletes the veth inside it, and with it its peer on the host.
        subprocess.run(["ip", "netns", "del", self.namespace], capture_output=True)
        subprocess.run(["ip", "link", "del", self.host_if], capture_output=True)

    def __enter__(self) -> EmulatedWifi:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.stop()
