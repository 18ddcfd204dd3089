"""The 3D view: how long from opening a run's view to the robot being in the scene, and what the
live view streams.

Starts `robodojo serve` on a free loopback port with a fresh data folder and measures, each over
--repeat fresh runs (median, max):

- websocket client (what the browser's viser client does after loading the page): GET
  /api/runs/{id}/viz/ (starts the run's viser server) -> websocket through the proxy -> the first
  frame that creates /robot, and the first that moves it to a pose from the run (/tf);
  "cold" is the server process's first view (viser imported then), "warm" the views after it,
  "again" a second visitor of a view already running;
- "again" both through the proxy and straight to viser's loopback port (the one the server
  logs), websocket only, so the proxy's share shows;
- a finished run (--replay-duration s of TurtleBot in the office, lockstep): opening its view
  loads the recording before the robot appears;
- Chromium (Debian's, headless, SwiftShader WebGL): navigation to .../viz -> the websocket
  frame that creates /robot, as seen by the page (page load and client start included);
- live stream over --stream-s seconds: /robot poses per second and bytes per second through the
  proxy for a CrowBot run (30 Hz expected: /tf is recorded at 30 Hz, the view draws at <= 30 Hz).

Usage: python bench/bench_viz.py [--repeat 5] [--stream-s 5] [--replay-duration 60] [--no-browser]
Target (issue 7): opening the view -> robot in the scene under 2 s.

Measured (2026-11-22, this container, viser 1.1.1, --repeat 5): cold 0.30 s (viser imported by
the first view), warm median 0.057 s (max 0.077), a second visitor 0.009 s proxied against
0.005 s straight to viser; a 60 s TurtleBot replay 0.21 s; Chromium navigation -> the /robot
frame median 0.66 s (max 0.76, the 819 KB client page and its start-up included); live stream
20 poses/s (the CrowBot's realtime /tf rate), 6.4 KiB/s.
"""

from __future__ import annotations

import argparse
import re
import statistics
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import viser
from websockets.sync.client import connect

from server.api.auth import SESSION_COOKIE
from tests.api.conftest import STEP_CONTROLLER, start_server, stop_server, wait_for_end
from tests.viz.conftest import viser_messages

SUBPROTOCOL = f"viser-v{viser.__version__}"
TURNING = "RATE_HZ = 20\n\n\ndef step(obs):\n    return {'Control': (0.0, 0.5)}\n"
PORT_LINE = re.compile(r"run (\w+): 3D view \((\w+)\) on 127\.0\.0\.1:(\d+)")


def start_run(client, robot="crowbot", world="wall_approach", duration_s=60.0, clock="realtime",
              exercise=None, code=STEP_CONTROLLER) -> str:  # fmt: skip
    body = {"nodes": [{"name": "node", "code": code}], "clock": clock, "duration": duration_s}
    body.update({"exercise": exercise} if exercise else {"robot": robot, "world": world})
    answer = client.post("/api/runs", json=body)
    answer.raise_for_status()
    return answer.json()["id"]


def until_robot(ws, started: float) -> tuple[float, float]:
    """(s to the frame creating /robot, s to the first /robot pose), from `started`."""
    created = moved = None
    while moved is None:
        for message in viser_messages(ws.recv(timeout=30)):
            if message.get("name") != "/robot":
                continue
            if message["type"] == "FrameMessage" and created is None:
                created = time.monotonic() - started
            if message["type"] == "SetPositionMessage" and created is not None:
                moved = time.monotonic() - started
    return created, moved


def open_view(
    lab, client, run_id: str, direct_port: int | None = None, page: bool = True
) -> tuple[float, float]:
    started = time.monotonic()
    cookie = client.cookies.get(SESSION_COOKIE)
    if direct_port is None:
        if page:
            client.get(f"/api/runs/{run_id}/viz/").raise_for_status()
        url = lab.url.replace("http", "ws", 1) + f"/api/runs/{run_id}/viz"
    else:
        url = f"ws://127.0.0.1:{direct_port}"
    with connect(url, subprotocols=[SUBPROTOCOL], max_size=None, origin=lab.url,
                 additional_headers={"Cookie": f"{SESSION_COOKIE}={cookie}"}) as ws:  # fmt: skip
        return until_robot(ws, started)


def viz_port(lab, run_id: str) -> int:
    for line in reversed(lab.output):
        match = PORT_LINE.search(line)
        if match and match.group(1) == run_id:
            return int(match.group(3))
    raise RuntimeError(f"no 3D view port logged for run {run_id}")


def stream(lab, client, run_id: str, seconds: float) -> tuple[float, float]:
    """(/robot turns per s, bytes per s) through the proxy, the robot turning in place."""
    client.get(f"/api/runs/{run_id}/viz/").raise_for_status()
    url = lab.url.replace("http", "ws", 1) + f"/api/runs/{run_id}/viz"
    cookie = client.cookies.get(SESSION_COOKIE)
    with connect(url, subprotocols=[SUBPROTOCOL], max_size=None, origin=lab.url,
                 additional_headers={"Cookie": f"{SESSION_COOKIE}={cookie}"}) as ws:  # fmt: skip
        until_robot(ws, time.monotonic())
        moves = size = 0
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            try:
                frame = ws.recv(timeout=max(0.01, end - time.monotonic()))
            except TimeoutError:
                break
            size += len(frame)
            moves += sum(
                m["type"] == "SetOrientationMessage" and m.get("name") == "/robot"
                for m in viser_messages(frame)
            )
    return moves / seconds, size / seconds


def browser_times(lab, student, run_ids: list[str]) -> list[float]:
    from playwright.sync_api import sync_playwright

    from tests.e2e.conftest import CHROMIUM, CHROMIUM_FLAGS

    times = []
    with sync_playwright() as playwright:
        browser = playwright.chromium.launch(
            executable_path=CHROMIUM, headless=True,
            args=[*CHROMIUM_FLAGS, "--use-gl=swiftshader", "--enable-unsafe-swiftshader"],
        )  # fmt: skip
        for run_id in run_ids:
            context = browser.new_context()
            page = context.new_page()
            page.goto(f"{lab.url}/login?token={student.token}")
            seen: dict[str, float] = {}

            def on_socket(ws, seen=seen):
                def on_frame(payload):
                    if "robot" in seen or isinstance(payload, str):
                        return
                    if any(m.get("name") == "/robot" for m in viser_messages(payload)):
                        seen["robot"] = time.monotonic()

                ws.on("framereceived", on_frame)

            page.on("websocket", on_socket)
            started = time.monotonic()
            page.goto(f"{lab.url}/api/runs/{run_id}/viz")
            deadline = time.monotonic() + 30
            while "robot" not in seen and time.monotonic() < deadline:
                page.wait_for_timeout(10)
            times.append(seen.get("robot", float("nan")) - started)
            context.close()
        browser.close()
    return times


def summary(name: str, values: list[float]) -> None:
    shown = ", ".join(f"{v:.3f}" for v in values)
    middle, worst = statistics.median(values), max(values)
    print(f"{name:<46} median {middle:.3f} s  max {worst:.3f} s  [{shown}]")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--stream-s", type=float, default=5.0)
    parser.add_argument("--replay-duration", type=float, default=60.0)
    parser.add_argument("--no-browser", action="store_true")
    args = parser.parse_args()
    lab = start_server(Path(tempfile.mkdtemp(prefix="bench-viz-")))
    try:
        created, moved, again, direct = [], [], [], []
        for index in range(args.repeat + 1):
            student = lab.student(f"viewer{index}")
            run_id = start_run(student)
            time.sleep(0.3)  # the run is going
            first = open_view(lab, student, run_id)
            created.append(first[0])
            moved.append(first[1])
            again.append(open_view(lab, student, run_id, page=False)[1])
            direct.append(open_view(lab, student, run_id, viz_port(lab, run_id))[1])
            student.post(f"/api/runs/{run_id}/stop")
        print(f"viser {viser.__version__}; {args.repeat} runs after the cold one")
        summary("cold: open -> /robot created", created[:1])
        summary("cold: open -> /robot at its pose", moved[:1])
        summary("warm: open -> /robot created", created[1:])
        summary("warm: open -> /robot at its pose", moved[1:])
        summary("again (view running): -> pose, proxied", again)
        summary("again (view running): -> pose, viser direct", direct)
        student = lab.student("streamer")
        run_id = start_run(student, code=TURNING)
        rate, bytes_s = stream(lab, student, run_id, args.stream_s)
        label = "live stream (crowbot turning)"
        print(f"{label:<46} {rate:.1f} /robot poses/s, {bytes_s / 1024:.1f} KiB/s")
        student.post(f"/api/runs/{run_id}/stop")
        student = lab.student("replayer")
        code = Path("server/exercises/reference/turtlebot_stanley.py").read_text()
        run_id = start_run(student, exercise="turtlebot_stanley", clock="lockstep", code=code,
                           duration_s=args.replay_duration)  # fmt: skip
        wait_for_end(student, run_id, timeout_s=600)
        mcap = Path(lab.data) / "runs" / run_id / "recording.mcap"
        replay = open_view(lab, student, run_id)
        print(f"replay of {args.replay_duration:.0f} s TurtleBot ({mcap.stat().st_size / 2**20:.1f}"
              f" MiB): open -> /robot at its pose {replay[1]:.3f} s")  # fmt: skip
        if not args.no_browser:
            student = lab.student("browser")
            run_ids = [start_run(student, duration_s=120) for _ in range(2)]
            times = browser_times(lab, student, run_ids)  # a fresh browser context each
            summary("chromium: navigate -> /robot frame", times)
            for run_id in run_ids:
                student.post(f"/api/runs/{run_id}/stop")
    finally:
        stop_server(lab)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
