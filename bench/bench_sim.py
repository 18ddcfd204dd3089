"""Simulator throughput: physics steps per second for each robot in its world.

Prints, per robot/world, the median and p99 over repeated batches of
- physics-only steps/s (a straight command through open space: motors, kinematics, odometry,
  contact bookkeeping; sensors not due), and
- full steps/s with every sensor topic publishing at its declared rate (what a run costs).

Usage: python bench/bench_sim.py [--seconds 2.0] [--repeats 7]
Target (issue 2): at least 20,000 CrowBot physics steps/s on one core.
"""

from __future__ import annotations

import argparse
import statistics
import time

from sandbox.msgs.geometry_msgs import Twist, Vector3
from sandbox.msgs.std_msgs import String
from server.sim import Simulation

CASES = [
    ("crowbot", "wall_approach", "Control", Twist(linear=Vector3(x=0.02), angular=Vector3(z=0.3))),
    ("crowbot", "line_track", "Control", Twist(linear=Vector3(x=0.05), angular=Vector3(z=0.4))),
    ("ir_scout", "obstacle_maze", "motor_command", String(data="left")),
    ("crop_rover", "crop_rows", "cmd_vel", Twist(linear=Vector3(x=0.05), angular=Vector3(z=0.2))),
    ("turtlebot", "office", "cmd_vel", Twist(linear=Vector3(x=0.05), angular=Vector3(z=0.3))),
]


def percentile(values: list[float], q: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, round(q * (len(ordered) - 1)))]


def measure(sim: Simulation, sim_seconds: float, physics_only: bool) -> float:
    if physics_only:
        # Push every sensor's next publication past the batch: only physics runs.
        sim._next_due_ns = {name: 1 << 62 for name in sim._next_due_ns}
        sim._earliest_due_ns = 1 << 62
    ticks = round(sim_seconds / sim._tick_s)
    start = time.perf_counter()
    sim.step(sim_seconds)
    return ticks / (time.perf_counter() - start)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=2.0, help="simulated seconds per batch")
    parser.add_argument("--repeats", type=int, default=7)
    args = parser.parse_args()
    print(f"{'robot':<11} {'world':<14} {'mode':<9} {'median steps/s':>15} {'p99 (slowest)':>14}")
    for robot, world, topic, command in CASES:
        for physics_only in (True, False):
            rates = []
            for repeat in range(args.repeats):
                sim = Simulation(robot, world, seed=repeat)
                sim.apply(topic, command)
                rates.append(measure(sim, args.seconds, physics_only))
            mode = "physics" if physics_only else "+sensors"
            # The p99 of a rate is its slow tail: the 1st percentile of steps/s.
            print(
                f"{robot:<11} {world:<14} {mode:<9} {statistics.median(rates):>15,.0f} "
                f"{percentile(rates, 0.01):>14,.0f}"
            )


if __name__ == "__main__":
    main()
