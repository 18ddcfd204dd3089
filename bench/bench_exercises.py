"""Wall time of `robodojo check EXERCISE --reference` for every exercise, as a user runs it
(a fresh process: interpreter start, sandbox start-up, every seed, the grading).

Usage: python bench/bench_exercises.py [--repeats 3]
Aim (issue 5): each under 5 s here.
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import time

from server.exercises.registry import exercise_ids, get_exercise


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    print(f"{'exercise':<24} {'runs':>5} {'sim s':>6} {'wall p50':>9} {'wall max':>9}  result")
    for exercise_id in exercise_ids():
        exercise = get_exercise(exercise_id)
        walls, verdict = [], "?"
        for _ in range(args.repeats):
            started = time.perf_counter()
            done = subprocess.run(
                [sys.executable, "-m", "server.cli", "check", exercise_id, "--reference"],
                capture_output=True,
                text=True,
                check=False,
            )
            walls.append(time.perf_counter() - started)
            verdict = "pass" if done.returncode == 0 else f"FAIL ({done.returncode})"
        runs = max(len(exercise.seeds), len(exercise.starts))  # one run per seed or start pose
        print(
            f"{exercise_id:<24} {runs:>5} "
            f"{exercise.duration_s * runs:>6.0f} "
            f"{statistics.median(walls):>8.2f}s {max(walls):>8.2f}s  {verdict}"
        )


if __name__ == "__main__":
    main()
