"""The editor's analysis as the server calls it (server/editor/service.py, no HTTP): completion
latency on a typical rospy node, and lint and format of the same file, one request after
another, as a student typing would. Measures what walling the analysis in (issue 33, findings
2, 5, 6) costs each request.

The node is 45 lines: a subscriber to a LaserScan, a Twist publisher, a rate loop; completions
are asked just after each `name.` attribute dot of the file, cycling through them (rospy.,
msg., cmd., np., math., self.). The first --warmup requests are not counted.

Prints p50, p95, p99 and max [ms] of each kind, and the CPU time the analysis' processes used
per round of the three (what a request costs the machine besides its latency).

Usage: python bench/bench_editor_sandbox.py [--requests 50] [--warmup 10] [--cache DIR]
       [--settle S]
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import psutil
from _common import percentile
from bench_editor import completion_points

from server.editor.context import RunContext
from server.editor.service import EditorService

NODE = '''\
#!/usr/bin/env python3
"""Wall follower: keeps the wall on the right at 0.5 m."""
import math

import numpy as np
import rospy
from geometry_msgs.msg import Twist
from sensor_msgs.msg import LaserScan

TARGET_M = 0.5  # [m]
GAIN = 1.2


class Follower:
    def __init__(self):
        self.publisher = rospy.Publisher("cmd_vel", Twist, queue_size=1)
        self.scan = None
        rospy.Subscriber("scan", LaserScan, self.on_scan)

    def on_scan(self, msg: LaserScan):
        self.scan = msg
        rospy.logdebug("ranges %d", len(msg.ranges))

    def command(self) -> Twist:
        cmd = Twist()
        if self.scan is None:
            return cmd
        ranges = np.array(self.scan.ranges)
        right = float(np.nanmin(ranges[len(ranges) // 4 :]))
        error = TARGET_M - right
        cmd.linear.x = 0.15
        cmd.angular.z = max(-1.0, min(1.0, GAIN * error + math.atan(error)))
        return cmd


def main():
    rospy.init_node("follower")
    follower = Follower()
    rate = rospy.Rate(10)
    while not rospy.is_shutdown():
        follower.publisher.publish(follower.command())
        rate.sleep()


main()
'''
READY_TIMEOUT_S = 300.0  # [s] the analysis' cold start on a loaded 2-core machine


def report(label: str, seconds: list[float]) -> None:
    ms = [s * 1e3 for s in seconds]
    print(f"{label:<10} p50 {percentile(ms, 0.5):7.1f}  p95 {percentile(ms, 0.95):7.1f}  "
          f"p99 {percentile(ms, 0.99):7.1f}  max {max(ms):7.1f}  [ms]  n={len(ms)}")  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--requests", type=int, default=50)
    parser.add_argument("--warmup", type=int, default=10)
    parser.add_argument("--cache", type=Path, default=None,
                        help="jedi's cache folder, kept between runs as a lab's data folder "
                        "keeps it (default: a new one, as at a lab's first start)")  # fmt: skip
    parser.add_argument("--settle", type=float, default=0.0,
                        help="[s] to wait once the analysis answers, for its warm-up of "
                        "matplotlib, scipy and scikit-fuzzy to end before measuring")  # fmt: skip
    args = parser.parse_args()
    service = EditorService(256 * 1024, cache_dir=args.cache)
    started = time.monotonic()
    service.start()
    context = RunContext("turtlebot3")
    while True:
        answer = service.complete("import rospy\nrospy.", 2, 6, context)
        if answer["completions"]:
            break
        if time.monotonic() - started > READY_TIMEOUT_S:
            raise SystemExit(f"the editor's analysis did not answer in {READY_TIMEOUT_S:g} s")
        time.sleep(0.5)
    print(f"analysis ready after {time.monotonic() - started:.1f} s; load average "
          f"{os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")  # fmt: skip
    time.sleep(args.settle)
    points = completion_points(NODE)
    timings: dict[str, list[float]] = {"complete": [], "lint": [], "format": []}
    empty = 0
    cpu_before_s = 0.0
    try:
        for index in range(args.warmup + args.requests):
            if index == args.warmup:
                cpu_before_s = analysis_cpu_s()
            line, column = points[index % len(points)]
            # A different constant each time, so no answer comes from a cache of the same text.
            code = NODE.replace("GAIN = 1.2", f"GAIN = 1.{index}")
            for kind, call, arguments in (
                ("complete", service.complete, (code, line, column, context)),
                ("lint", service.lint, (code, context)),
                ("format", service.format, (code,)),
            ):
                start = time.perf_counter()
                answer = call(*arguments)
                elapsed = time.perf_counter() - start
                if index >= args.warmup:
                    timings[kind].append(elapsed)
                    empty += kind == "complete" and not answer["completions"]
        cpu_ms = (analysis_cpu_s() - cpu_before_s) * 1e3 / args.requests
    finally:
        service.close()
    for kind, seconds in timings.items():
        report(kind, seconds)
    print(f"completions with an empty list: {empty} of {args.requests}")
    print(f"CPU of the analysis' processes: {cpu_ms:.0f} ms per completion + lint + format")


def analysis_cpu_s() -> float:
    """CPU time [s] the analysis' processes (this one's descendants) have used, those that
    ended included (counted in their parents' children times)."""
    total = 0.0
    for process in psutil.Process().children(recursive=True):
        try:
            times = process.cpu_times()
        except psutil.NoSuchProcess:
            continue
        total += times.user + times.system + times.children_user + times.children_system
    return total


if __name__ == "__main__":
    main()
