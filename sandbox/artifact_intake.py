"""The parent's check of the files a node sends with its end (`Exited.artifacts`), whatever the
node's code did to the collector inside its sandbox (sandbox/artifacts.py).

The collector applies the caps of sandbox.limits, but it runs in the student's process: a node
that replaced its own `collect_artifacts` once sent 20,002 files, or one of 40 MiB, and a
student's runs reached 960 MiB of disk against a 500 MiB budget. So every `Exited` frame a node
sends is held here, on the server's side of the pipe, to the same caps (count, per-file size,
total) and to names the collector could have made: a relative path of non-empty parts, none of
them ".", ".." or hidden (a leading "."), no control characters, no name twice, at most
`artifact_name_chars` characters. A refused file is dropped and said in a note (the run's log
shows it under "[artifacts]"); the node's own notes are capped too, in count and length.

    exited = accept_artifacts(exited, limits)    # sandbox/node_process.py, on every Exited
    exited = within_run_room(exited, limits, room_bytes)  # node_host.py: a run's nodes together
"""

from __future__ import annotations

import msgspec

from sandbox.limits import Limits, MiB
from sandbox.protocol import Artifact, Exited

# Notes of each kind kept (the node's own, then the refusals); past them one sentence counts the
# rest. The collector writes one per skipped file, so a node that wrote 20,000 files would
# otherwise fill its log with them.
NOTES_KEPT = 32


def _mb(size_bytes: int) -> str:
    value = size_bytes / MiB
    return f"{value:.0f} MB" if value == int(value) else f"{value:.1f} MB"


def name_problem(name: str, limits: Limits) -> str | None:
    """Why `name` is not one the collector could have sent, or None when it is fine."""
    if not name:
        return "it has no name"
    if len(name) > limits.artifact_name_chars:
        return f"its name is longer than {limits.artifact_name_chars} characters"
    if any(ord(char) < 32 or ord(char) == 127 for char in name):
        return "its name has control characters"
    for part in name.split("/"):
        if part in ("", ".", ".."):
            return "its name is not a path inside the node's folder"
        if part.startswith("."):
            return "its name is hidden (starts with a dot)"
    return None


def _shown(name: str) -> str:
    """A refused name as a note shows it: printable, and short."""
    text = "".join(char if char.isprintable() else "?" for char in name)
    return text if len(text) <= 80 else text[:77] + "..."


class _Notes:
    """Notes of one kind: the first NOTES_KEPT, then a count of the others."""

    def __init__(self, line_chars: int) -> None:
        self.kept: list[str] = []
        self.left_out = 0
        self.line_chars = line_chars  # a note is one line of the node's log

    def add(self, note: str) -> None:
        if len(self.kept) < NOTES_KEPT:
            self.kept.append(note[: self.line_chars])
        else:
            self.left_out += 1


def accept_artifacts(exited: Exited, limits: Limits) -> Exited:
    """`exited` as the server keeps it: only the artifacts within `limits` (in the order
    sent), the node's notes capped, and notes that say what was refused and why."""
    line_chars = limits.log_line_bytes
    quiet = len(exited.notes) <= NOTES_KEPT and all(len(n) <= line_chars for n in exited.notes)
    if quiet and not exited.artifacts:
        return exited
    own = _Notes(line_chars)
    for note in exited.notes:
        own.add(note)
    notes = own.kept
    if own.left_out:
        notes.append(f"{own.left_out} more notes of the node left out")
    accepted, refusals = _accept(exited.artifacts, limits, limits.artifact_total_bytes)
    return msgspec.structs.replace(exited, artifacts=accepted, notes=notes + refusals)


def within_run_room(exited: Exited, limits: Limits, room_bytes: int) -> Exited:
    """`exited` (already through `accept_artifacts`) with only the files that fit in
    `room_bytes`, what the run's other nodes left of the total cap: it holds for a run's
    nodes together (server/runs/node_host.py). Notes for the files left out are added."""
    if sum(len(artifact.data) for artifact in exited.artifacts) <= room_bytes:
        return exited
    accepted, refusals = _accept(exited.artifacts, limits, max(0, room_bytes), run_room=True)
    return msgspec.structs.replace(exited, artifacts=accepted, notes=[*exited.notes, *refusals])


def _accept(
    artifacts: list[Artifact], limits: Limits, total_cap: int, run_room: bool = False
) -> tuple[list[Artifact], list[str]]:
    """(the artifacts kept, a note for each refused or a count of them)."""
    if run_room:
        over_total = f"over the {_mb(limits.artifact_total_bytes)} the nodes of a run may save"
    else:
        over_total = f"over the {_mb(total_cap)} total cap for all files"
    refused = _Notes(limits.log_line_bytes)
    accepted: list[Artifact] = []
    names: set[str] = set()
    total = 0
    over_count = 0
    for artifact in artifacts:
        name, size = artifact.name, len(artifact.data)
        problem = name_problem(name, limits)
        if problem is None and name in names:
            problem = "a file of that name came already"
        if problem is not None:
            refused.add(f"{_shown(name)} refused by the server: {problem}")
            continue
        if len(accepted) >= limits.artifact_count:
            over_count += 1
            continue
        if size > limits.artifact_file_bytes:
            refused.add(
                f"{name} ({_mb(size)}) refused by the server: over the "
                f"{_mb(limits.artifact_file_bytes)} per-file cap"
            )
            continue
        if total + size > total_cap:
            refused.add(f"{name} ({_mb(size)}) refused by the server: {over_total}")
            continue
        names.add(name)
        total += size
        accepted.append(artifact)
    notes = refused.kept
    if refused.left_out:
        notes.append(f"{refused.left_out} more files refused by the server, for the same reasons")
    if over_count:
        notes.append(
            f"{over_count} more files refused by the server: over the "
            f"{limits.artifact_count} file cap"
        )
    return accepted, notes
