"""Files the node wrote in its working directory, collected as run artifacts.

Regular files only (symlinks are skipped, never followed), named relative to the directory, in
sorted order. Hidden files and directories are not collected: the scratch directory is also the
node's HOME, where matplotlib keeps its font cache (.matplotlib/). The caps of sandbox.limits
apply per file, in total and in count; a file over a cap is skipped with a note for the student,
never an exception.
"""

from __future__ import annotations

import os
import stat

from sandbox.limits import DEFAULT_LIMITS, Limits, MiB
from sandbox.protocol import Artifact


def _mb(size_bytes: int) -> str:
    value = size_bytes / MiB
    return f"{value:.0f} MB" if value == int(value) else f"{value:.1f} MB"


def _regular_files(workdir: str) -> list[str]:
    found: list[str] = []
    for folder, dirs, files in os.walk(workdir, followlinks=False):
        dirs[:] = sorted(d for d in dirs if not d.startswith(".") and d != "__pycache__")
        for name in files:
            if name.startswith("."):
                continue
            path = os.path.join(folder, name)
            try:
                if stat.S_ISREG(os.lstat(path).st_mode):
                    found.append(os.path.relpath(path, workdir))
            except OSError:
                continue
    return sorted(found)


def write_workspace_files(workdir: str, files: list[Artifact]) -> dict[str, bytes]:
    """Copy the student's workspace data files into the node's working directory (copy on
    run: the node may change its copy; the workspace keeps the original). Returns what was
    written, so `collect_artifacts` can leave unchanged inputs out of the artifacts. A path
    that would leave the directory is skipped (the server checks paths too)."""
    written: dict[str, bytes] = {}
    for file in files:
        name = os.path.normpath(file.name)
        parts = name.split(os.sep)
        if os.path.isabs(name) or any(part in ("", "..") or part.startswith(".") for part in parts):
            continue
        path = os.path.join(workdir, name)
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with open(path, "wb") as out:
            out.write(file.data)
        written[name] = file.data
    return written


def collect_artifacts(
    workdir: str, limits: Limits = DEFAULT_LIMITS, inputs: dict[str, bytes] | None = None
) -> tuple[list[Artifact], list[str]]:
    """(artifacts, notes) for the files in `workdir`, within the caps of `limits`; workspace
    files in `inputs` come back only if the node changed them."""
    inputs = inputs or {}
    artifacts: list[Artifact] = []
    notes: list[str] = []
    total = 0
    try:
        names = _regular_files(workdir)
    except OSError as error:
        return [], [f"could not list the working directory: {error.strerror}"]
    for name in names:
        path = os.path.join(workdir, name)
        if len(artifacts) >= limits.artifact_count:
            notes.append(f"{name} skipped: over the {limits.artifact_count} file cap")
            continue
        try:
            with open(path, "rb") as file:
                # Read one byte past the cap, so a file growing after a stat cannot slip by.
                data = file.read(limits.artifact_file_bytes + 1)
                size = os.fstat(file.fileno()).st_size
        except OSError as error:
            notes.append(f"{name} skipped: {error.strerror}")
            continue
        size = max(size, len(data))
        if inputs.get(name) == data:
            continue  # a workspace file the node only read
        if size > limits.artifact_file_bytes:
            notes.append(
                f"{name} ({_mb(size)}) skipped: over the {_mb(limits.artifact_file_bytes)} "
                "per-file cap"
            )
            continue
        if total + size > limits.artifact_total_bytes:
            notes.append(
                f"{name} ({_mb(size)}) skipped: over the {_mb(limits.artifact_total_bytes)} "
                "total cap for all files"
            )
            continue
        total += size
        artifacts.append(Artifact(name=name, data=data))
    return artifacts, notes
