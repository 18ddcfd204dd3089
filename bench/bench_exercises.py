"""Wall time of `robodojo check EXERCISE --reference` for every exercise, as a user runs it
(a fresh process: interpreter start, sandbox start-up, every seed, the grading), and the CPU
time it took across its whole process tree (the CLI, its grading workers, every sandboxed node).

Usage: python bench/bench_exercises.py [--repeats 5] [--only ID ...]
Aim (issue 18): each under 5 s wall here (2 cores). The machine is shared: when other work runs,
the wall grows while the CPU seconds stay put, so read both (the CPU divided by 2 cores is the
wall a quiet machine would give at best).
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import threading
import time

import psutil

from server.exercises.registry import exercise_ids, get_exercise

SAMPLE_EVERY_S = 0.02  # [s] how often the process tree's CPU times are read


def percentile(values: list[float], q: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, round(q * (len(ordered) - 1)))]


def tree_cpu_s(command: list[str]) -> tuple[float, float, int]:
    """Run `command`; its wall [s], the CPU [s] of it and every process under it, its exit code.

    A sandboxed node's CPU never reaches the CLI's rusage (bubblewrap's PID namespace reaps it),
    so the tree is sampled: each process's last reading counts (one shorter than a sample is
    missed, a few ms)."""
    cpu_by_pid: dict[int, float] = {}
    started = time.perf_counter()
    child = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    root = psutil.Process(child.pid)
    done = threading.Event()

    def sample() -> None:
        while not done.is_set():
            try:
                processes = [root, *root.children(recursive=True)]
            except psutil.Error:
                processes = []
            for process in processes:
                try:
                    times = process.cpu_times()
                except psutil.Error:
                    continue
                cpu_by_pid[process.pid] = times.user + times.system
            done.wait(SAMPLE_EVERY_S)

    sampler = threading.Thread(target=sample, daemon=True)
    sampler.start()
    code = child.wait()
    wall_s = time.perf_counter() - started
    done.set()
    sampler.join()
    return wall_s, sum(cpu_by_pid.values()), code


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--only", nargs="*", default=None, help="exercise ids (default: all)")
    args = parser.parse_args()
    print(
        f"{'exercise':<24} {'runs':>4} {'sim s':>6} {'wall p50':>9} {'wall p99':>9} "
        f"{'cpu p50':>8} {'cpu p99':>8}  result"
    )
    for exercise_id in args.only or exercise_ids():
        exercise = get_exercise(exercise_id)
        walls, cpus, verdicts = [], [], set()
        for _ in range(args.repeats):
            command = [sys.executable, "-m", "server.cli", "check", exercise_id, "--reference"]
            wall_s, cpu_s, code = tree_cpu_s(command)
            walls.append(wall_s)
            cpus.append(cpu_s)
            verdicts.add("pass" if code == 0 else f"FAIL ({code})")
        runs = max(len(exercise.seeds), len(exercise.starts))  # one run per seed or start pose
        print(
            f"{exercise_id:<24} {runs:>4} {exercise.duration_s * runs:>6.0f} "
            f"{statistics.median(walls):>8.2f}s {percentile(walls, 0.99):>8.2f}s "
            f"{statistics.median(cpus):>7.2f}s {percentile(cpus, 0.99):>7.2f}s  "
            f"{', '.join(sorted(verdicts))}",
            flush=True,
        )


if __name__ == "__main__":
    main()
