"""File names that come from students (node names, artifact names) made safe to write under a
run's folder: no "..", no absolute paths, no separators in a single name, nothing that resolves
outside the folder through a symlink."""

from __future__ import annotations

import re
from pathlib import Path

_MAX_NAME_CHARS = 100  # [chars] per path component of a log or artifact name
_MAX_ARTIFACT_DEPTH = 8  # [dirs] sub-directories kept from an artifact name
_UNSAFE_CHARS = re.compile(r"[^\w.\-]+")


def _path_parts(name: str) -> list[str]:
    """The parts of `name` split at "/" and "\\", without empty, "." and ".." parts."""
    return [part for part in re.split(r"[/\\]+", str(name)) if part not in ("", ".", "..")]


def safe_name(name: str) -> str:
    """One path component made from `name`: "." and ".." parts are dropped, separators and
    other unsafe characters become "_", leading/trailing dots go; never empty."""
    parts = _path_parts(name)
    cleaned = _UNSAFE_CHARS.sub("_", "_".join(parts)).strip(".")
    return cleaned[:_MAX_NAME_CHARS] or "_"


def safe_relative_path(name: str) -> Path:
    """A relative path made from an artifact name: sub-directories are kept, but "..", ".",
    empty parts and a leading "/" are dropped, so 'a/../../b' -> 'a/b', '/etc/x' -> 'etc/x'."""
    parts = _path_parts(name)
    if not parts:
        return Path("_")
    kept = parts[-(_MAX_ARTIFACT_DEPTH + 1) :]
    return Path(*(safe_name(part) for part in kept))


def inside(root: Path, relative: Path) -> Path:
    """`root / relative`, checked to resolve inside `root` (symlinks included)."""
    target = root / relative
    if not target.resolve().is_relative_to(root.resolve()):
        raise ValueError(f"refusing to write {relative}: it resolves outside {root}")
    return target
