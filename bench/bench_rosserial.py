"""rosserial round trip over loopback: a sensor frame from the robot to the command it causes.

The CrowBot firmware emulator (tests/hardware/crowbot_firmware.py) publishes Distance = 1, 2, 3...
with its other three topics at each loop rate; a trivial host-side handler answers every
Distance with a Control carrying the same number (in linear.z, which the robot ignores). The
emulator timestamps each Distance just before writing it and each Control as it decodes it;
the difference is the round trip through the server (socket, parser, session, handler, send).

The emulator runs in its own process by default (like a real robot: no shared GIL with the
server); --same-process runs it in a thread. The emulator waits on its socket between loop
ticks, so the numbers are the host's and the link's. A firmware that only reads in loop()
(CrowBotROSV2.ino: publish, spinOnce(), delay(1)) sees the answer at its next spinOnce(), up to
one loop period later; the paper measured at the robot that way.

The paper (000_32b6074bbd2115c3.txt, section 3.5, Figs. 18 and 19) gives its response times only
as plots: at 10 Hz "a consistent sampling time of 0.1 seconds", at 20 Hz "more significant
variations ... the robot starts to encounter difficulties", hence its choice of 10 Hz. The text
states no latency figures to compare with.

Over emulated WiFi (--wifi, as root where network namespaces can be made): the emulator runs in
its own network namespace behind a veth pair (2 Mbit tbf) and a relay that adds 20 ms +- 10 ms
one way and retransmits 2 % of segments 200 ms late (tests/hardware/emulated_wifi.py); the same
rates are measured over it beside loopback.

--freeze S: the latest-wins check instead: command a robot process at 20 Hz, SIGSTOP it for S
seconds, send the stop, resume it, and count what it receives (tests/hardware/
test_rosserial_latest_wins.py).

Usage: python bench/bench_rosserial.py [--duration 5] [--rates 10 20 50 100] [--same-process]
       [--wifi] [--freeze 10]
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import statistics
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from sandbox.msgs import Message
from sandbox.msgs.geometry_msgs import Twist, Vector3
from server.hardware.rosserial import RobotConnection, RosserialHandler, RosserialServer
from tests.hardware.crowbot_firmware import CrowBotFirmware, FirmwareOptions
from tests.hardware.emulated_wifi import RELAY_PORT, EmulatedWifi, namespaces_unavailable
from tests.hardware.test_rosserial_latest_wins import freeze_and_count

LOOPBACK = "127.0.0.1"


class Echo(RosserialHandler):
    """Answers each Distance with a Control that carries the Distance's number."""

    def __init__(self) -> None:
        self.connected = 0

    def on_robot_connected(self, robot: RobotConnection) -> None:
        self.connected += 1

    def on_message(self, robot: RobotConnection, topic: str, message: Message) -> None:
        if topic == "Distance":
            robot.send("Control", Twist(linear=Vector3(z=float(message.data))))


def run_emulator(port: int, rate_hz: float, duration_s: float) -> tuple[list[float], int]:
    """Round trips [s] measured by one emulator run, and the number of Distances sent."""
    options = FirmwareOptions(rate_hz=rate_hz, counter_distance=True)
    with CrowBotFirmware(LOOPBACK, port, options) as robot:
        robot.wait_until(lambda: robot.configured, timeout_s=5.0)
        time.sleep(0.5)  # settle: negotiation, first time sync
        robot.distance_sent.clear()
        robot.received.clear()
        time.sleep(duration_s)
        sent = dict((value, t) for t, value in list(robot.distance_sent))
        answers = [
            (t, int(m.linear.z)) for t, topic, m in list(robot.received) if topic == "Control"
        ]
    return [t - sent[value] for t, value in answers if value in sent], len(sent)


def _child(port: int, rate_hz: float, duration_s: float, results: multiprocessing.Queue) -> None:
    results.put(run_emulator(port, rate_hz, duration_s))


def percentile(values: list[float], q: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, round(q * (len(ordered) - 1)))]


def measure_wifi(rate_hz: float, duration_s: float) -> tuple[list[float], int]:
    """The emulator in its own namespace, through the emulated WiFi link (module docstring)."""
    with (
        RosserialServer(Echo(), host="0.0.0.0", port=0) as server,
        EmulatedWifi().start(server.port) as wifi,
    ):
        child = subprocess.run(
            [*wifi.prefix, sys.executable, str(Path(__file__).resolve()), "--child",
             "--rates", str(rate_hz), "--duration", str(duration_s)],
            capture_output=True, text=True, timeout=duration_s + 60, check=False,
        )  # fmt: skip
        if child.returncode != 0:
            raise RuntimeError(f"the emulator in the namespace failed: {child.stderr[-2000:]}")
        round_trips, sent = json.loads(child.stdout.strip().splitlines()[-1])
        return round_trips, sent


def measure(rate_hz: float, duration_s: float, same_process: bool) -> tuple[list[float], int]:
    with RosserialServer(Echo(), host=LOOPBACK, port=0) as server:
        if same_process:
            return run_emulator(server.port, rate_hz, duration_s)
        context = multiprocessing.get_context("spawn")
        results = context.Queue()
        child = context.Process(target=_child, args=(server.port, rate_hz, duration_s, results))
        child.start()
        outcome = results.get(timeout=duration_s + 30)
        child.join(10)
        return outcome


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", type=float, default=5.0, help="[s] measured per rate")
    parser.add_argument("--rates", type=float, nargs="+", default=[10.0, 20.0, 50.0, 100.0])
    parser.add_argument("--same-process", action="store_true", help="emulator in a thread")
    parser.add_argument("--wifi", action="store_true", help="also over emulated WiFi (root)")
    parser.add_argument("--freeze", type=float, help="[s] measure a frozen robot's backlog")
    parser.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:  # inside the namespace: the emulator dials the relay, prints its figures
        print(json.dumps(run_emulator(RELAY_PORT, args.rates[0], args.duration)))
        return
    if args.freeze is not None:
        after, sent = freeze_and_count(args.freeze)
        print(
            f"robot frozen {args.freeze:g} s while commanded at 20 Hz: {sent} commands sent "
            f"meanwhile; after resuming it received {len(after)} Control(s), "
            f"{sum(r.bytes for r in after)} bytes, the last {after[-1].linear if after else None}"
        )
        return
    where = "the same process" if args.same_process else "a separate process"
    links = ["loopback"]
    if args.wifi:
        reason = namespaces_unavailable()
        if reason is None:
            links.append("wifi")
        else:
            print(f"emulated WiFi skipped: {reason}")
    print(f"Distance -> Control round trip, emulator in {where} (WiFi: in its namespace)")
    print(
        f"{'link':>8} {'rate':>6} {'samples':>8} {'answered':>9} {'p50 [ms]':>9} "
        f"{'p99 [ms]':>9} {'max [ms]':>9} {'+1 loop [ms]':>13}"
    )
    for link in links:
        for rate_hz in args.rates:
            if link == "wifi":
                round_trips, sent = measure_wifi(rate_hz, args.duration)
            else:
                round_trips, sent = measure(rate_hz, args.duration, args.same_process)
            if not round_trips:
                print(f"{link:>8} {rate_hz:>5.0f}Hz {sent:>8} {'none':>9}")
                continue
            ms = [1000 * value for value in round_trips]
            print(
                f"{link:>8} {rate_hz:>5.0f}Hz {sent:>8} {len(ms) / max(sent, 1):>8.1%} "
                f"{statistics.median(ms):>9.2f} {percentile(ms, 0.99):>9.2f} {max(ms):>9.2f} "
                f"{1000 / rate_hz:>13.1f}"
            )
    print(
        "'+1 loop' is the extra delay a firmware that reads only once per loop adds at worst.\n"
        "Paper (section 3.5, Figs. 18-19): plots only; 10 Hz steady at 0.1 s, 20 Hz more varied."
    )


if __name__ == "__main__":
    main()
