"""Microseconds per simulated scan: the 360-degree LiDAR in the crop field and the depth scan in the
office, median and p99 over a few thousand scans taken along a path through each world.

Run from the repository root: `python3 -m bench.bench_scans [scans]`.
Target: a 360-degree scan under 2 ms on one core.
"cast" is the median time spent in `Obstacles.cast` per scan, to tell the ray caster's share from
the sensor's own work (noise, validity, building the message). Wall-clock timing is fine here:
this is a benchmark, outside the simulator. Other processes on the machine widen the p99.
"""

from __future__ import annotations

import math
import sys
import time

import numpy as np

from server.sim.obstacles import Obstacles
from server.sim.sensors.base import SenseContext
from server.sim.sensors.depth_scan import DepthScan
from server.sim.sensors.lidar import Lidar2D
from server.sim.state import Pose2D, RobotState
from server.sim.world import World, load_world

DEFAULT_SCANS = 2000


def poses_along_spawn(world: World, count: int, length_m: float) -> list[Pose2D]:
    """Poses driving `length_m` straight ahead from the default spawn with a gentle weave."""
    spawn = world.spawn()
    poses = []
    for k in range(count):
        along = length_m * k / count
        weave = 0.1 * math.sin(k / 50.0)
        poses.append(
            Pose2D(
                x=spawn.x + along * math.cos(spawn.yaw) - weave * math.sin(spawn.yaw),
                y=spawn.y + along * math.sin(spawn.yaw) + weave * math.cos(spawn.yaw),
                yaw=spawn.yaw + 0.1 * math.sin(k / 80.0),
            )
        )
    return poses


class _TimedObstacles:
    """Wraps `Obstacles` to time each cast."""

    def __init__(self, obstacles: Obstacles) -> None:
        self._obstacles = obstacles
        self.cast_ns = 0

    def cast(self, *args: object, **kwargs: object) -> object:
        start = time.perf_counter_ns()
        hits = self._obstacles.cast(*args, **kwargs)
        self.cast_ns = time.perf_counter_ns() - start
        return hits


def bench(sensor: object, world: World, scans: int, path_m: float) -> tuple[np.ndarray, np.ndarray]:
    """Per-scan times [us], whole sample and inside the ray caster."""
    obstacles = _TimedObstacles(Obstacles(world))
    rng = np.random.default_rng(0)
    durations = np.empty(scans)
    casting = np.empty(scans)
    for k, pose in enumerate(poses_along_spawn(world, scans, path_m)):
        ctx = SenseContext(
            world=world,
            obstacles=obstacles,  # type: ignore[arg-type]
            state=RobotState(pose=pose),
            time_s=k / 7.0,
            lights=(),
        )
        start = time.perf_counter_ns()
        sensor.sample(ctx, rng)
        durations[k] = (time.perf_counter_ns() - start) / 1000.0
        casting[k] = obstacles.cast_ns / 1000.0
    return durations, casting


def report(name: str, durations: np.ndarray, casting: np.ndarray) -> None:
    median_us, p99_us = np.median(durations), np.percentile(durations, 99)
    print(
        f"{name:<34} median {median_us:7.1f} us   p99 {p99_us:7.1f} us"
        f"   cast median {np.median(casting):7.1f} us"
    )


def main() -> None:
    scans = int(sys.argv[1]) if len(sys.argv) > 1 else DEFAULT_SCANS
    crop = load_world("crop_rows")
    office = load_world("office")
    lidar = Lidar2D()
    print(f"{scans} scans each; crop_rows: {len(crop.circles)} plants, {len(crop.segments)} walls")
    report(f"Lidar2D ({lidar.beam_count} beams) crop_rows", *bench(lidar, crop, scans, 4.0))
    depth = DepthScan()
    print(f"office: {len(office.segments)} segments, {len(office.circles)} cylinders")
    report(f"DepthScan ({depth.beam_count} beams) office", *bench(depth, office, scans, 2.0))
    report(f"Lidar2D ({lidar.beam_count} beams) office", *bench(lidar, office, scans, 2.0))


if __name__ == "__main__":
    main()
