"""Where each process's Python heap goes: `bench_cluster.py --tracemalloc` (scenario c).

The lab's processes start with bench/_heap_site on PYTHONPATH (`environment`): its
sitecustomize traces every allocation from the first import and writes a tracemalloc snapshot
when the process gets SIGUSR2. Scenario c asks every web and worker process for one snapshot
after its warm-up and one at the end of its window (`snapshot_all`); `compare` groups both by
allocation site and `report` prints, per process, the sites that grew most:

    site                                   warm-up [MiB]  late [MiB]  growth [MiB/min]

A site is the newest frame of the allocation's traceback that is RoboDojo's own code (server/,
sandbox/), with the line that allocated beside it when that line is a library's or the
standard library's: "server/runs/recording.py:120 <- mcap/writer.py:260" says which of our
lines keeps the memory and which library holds it. An allocation with no frame of ours (an
import, a thread of a library) is its allocating line alone.

tracemalloc sees what Python allocates (objects, numpy buffers); RSS also holds the
allocator's free but unreturned pages, the C libraries' own memory and the interpreter. The
report gives both totals. Tracing slows a process two to three times over: use this pass for
the heap, and a pass without it for latencies and RSS slopes.
"""

from __future__ import annotations

import asyncio
import os
import signal
import time
import tracemalloc
from collections import defaultdict
from dataclasses import dataclass
from pathlib import Path

import psutil
from _common import MIB, ROOT

HEAP_DIR_ENV = "ROBODOJO_BENCH_HEAP_DIR"  # read by bench/_heap_site/sitecustomize.py
SITE_DIR = Path(__file__).resolve().parent / "_heap_site"
OUR_CODE = tuple(str(ROOT / package) + os.sep for package in ("server", "sandbox"))
SNAPSHOT_TIMEOUT_S = 300.0  # [s] a traced process of ~100 MiB writes its snapshot in seconds
TOP_SITES = 12  # sites listed per process
TOP_FILES = 6  # files listed per process (a site's own file, summed)


def environment(heap_dir: Path) -> dict[str, str]:
    """What the lab's processes need in their environment to be traced."""
    return {HEAP_DIR_ENV: str(heap_dir), "PYTHONPATH": os.pathsep.join((str(ROOT), str(SITE_DIR)))}


async def snapshot_all(processes: dict[str, psutil.Process], heap_dir: Path) -> dict[str, Path]:
    """Ask each process for its next snapshot; wait for them all. name -> the snapshot file."""
    before = {name: set(heap_dir.glob(f"{p.pid}-*.tracemalloc")) for name, p in processes.items()}
    for name, process in processes.items():
        try:
            process.send_signal(signal.SIGUSR2)
        except psutil.Error:
            before.pop(name)  # ended meanwhile: no snapshot from it
    found: dict[str, Path] = {}
    deadline = time.monotonic() + SNAPSHOT_TIMEOUT_S
    while len(found) < len(before) and time.monotonic() < deadline:
        for name, old in before.items():
            new = set(heap_dir.glob(f"{processes[name].pid}-*.tracemalloc")) - old
            if new:
                found[name] = max(new, key=lambda path: int(path.stem.split("-")[1]))
        await asyncio.sleep(0.5)
    return found


def _short(filename: str) -> str:
    """A frame's file as a reader knows it: relative to the checkout, site-packages or stdlib."""
    if filename.startswith(str(ROOT) + os.sep):
        return os.path.relpath(filename, ROOT)
    for marker in ("site-packages" + os.sep, "lib" + os.sep + "python3."):
        at = filename.rfind(marker)
        if at >= 0:
            rest = filename[at + len(marker) :]
            return rest if marker.startswith("site") else "stdlib/" + rest.partition(os.sep)[2]
    return filename


def site_of(traceback: tracemalloc.Traceback) -> tuple[str, str]:
    """(site, its file): our newest frame, "<- the allocating line" when that is not ours."""
    newest = traceback[-1]  # tracemalloc orders a traceback oldest first
    for frame in reversed(traceback):
        if frame.filename.startswith(OUR_CODE):
            ours = f"{_short(frame.filename)}:{frame.lineno}"
            if frame == newest:
                return ours, _short(frame.filename)
            return f"{ours} <- {_short(newest.filename)}:{newest.lineno}", _short(frame.filename)
    return f"{_short(newest.filename)}:{newest.lineno}", _short(newest.filename)


def _sizes(path: Path) -> tuple[dict[str, int], dict[str, int], int]:
    """Bytes per site and per file in one snapshot, and its total."""
    snapshot = tracemalloc.Snapshot.load(str(path)).filter_traces(
        [tracemalloc.Filter(False, tracemalloc.__file__)]
    )
    sites: dict[str, int] = defaultdict(int)
    files: dict[str, int] = defaultdict(int)
    total = 0
    for stat in snapshot.statistics("traceback"):
        site, filename = site_of(stat.traceback)
        sites[site] += stat.size
        files[filename] += stat.size
        total += stat.size
    return sites, files, total


@dataclass
class Row:
    where: str
    early_mib: float
    late_mib: float
    growth_mib_per_min: float


def _rows(early: dict[str, int], late: dict[str, int], minutes: float, top: int) -> list[Row]:
    rows = [
        Row(key, early.get(key, 0) / MIB, late.get(key, 0) / MIB, 0.0)
        for key in set(early) | set(late)
    ]
    for row in rows:
        row.growth_mib_per_min = (row.late_mib - row.early_mib) / minutes
    rows.sort(key=lambda row: row.growth_mib_per_min, reverse=True)
    return rows[:top]


def compare(early: Path, late: Path, minutes: float) -> dict:
    """One process's two snapshots: its totals, the sites and files that grew most."""
    early_sites, early_files, early_total = _sizes(early)
    late_sites, late_files, late_total = _sizes(late)
    return {
        "minutes": minutes,
        "traced_mib": (early_total / MIB, late_total / MIB),
        "sites": [vars(r) for r in _rows(early_sites, late_sites, minutes, TOP_SITES)],
        "files": [vars(r) for r in _rows(early_files, late_files, minutes, TOP_FILES)],
    }


def report(name: str, figures: dict, rss_mib: tuple[float, float]) -> None:
    early, late = figures["traced_mib"]
    minutes = figures["minutes"]
    print(
        f"  {name}: traced heap {early:.1f} -> {late:.1f} MiB "
        f"({(late - early) / minutes:+.3f} MiB/min over {minutes:.1f} min); "
        f"RSS {rss_mib[0]:.1f} -> {rss_mib[1]:.1f} MiB"
    )
    for title, key in (("site", "sites"), ("file (its sites summed)", "files")):
        print(f"    {title:<78} {'warm-up':>8} {'late':>8} {'MiB/min':>8}")
        for row in figures[key]:
            print(
                f"    {row['where'][:78]:<78} {row['early_mib']:8.2f} {row['late_mib']:8.2f} "
                f"{row['growth_mib_per_min']:+8.3f}"
            )
