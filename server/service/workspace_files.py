"""What a workspace may hold: node code (`.py`; `.launch.py` for a ROS 2 launch file) and the
text data files a ROS package keeps next to it (CSV, YAML, JSON, TXT, `.launch` and `.xml`), by
name, kind and size. Every refusal is a
sentence that names the file and says what to do.

Names are relative paths of at most three parts ("waypoints.csv", "config/gains.yaml",
"launch/two.launch"), so a launch file's `$(find pkg)/config/x.yaml` finds its file. Nothing
that could leave the node's working directory is accepted (absolute paths, "..", hidden files,
backslashes); the sandbox checks again when it writes the files (sandbox/artifacts.py)."""

from __future__ import annotations

import re
from collections.abc import Iterable
from dataclasses import dataclass

CODE_EXTENSION = ".py"
DATA_EXTENSIONS = (".csv", ".yaml", ".yml", ".json", ".txt", ".launch", ".xml")
LAUNCH_PY_SUFFIX = ".launch.py"  # a ROS 2 Python launch file: code, but never a node
MAX_NAME_CHARS = 64  # the store's file name column
MAX_PARTS = 3  # folder depth: a package's config/ or launch/ folder, not a tree
_PART = re.compile(r"^[A-Za-z0-9_][A-Za-z0-9_.\-]*$")
_NODE_STEM = re.compile(r"^[A-Za-z][A-Za-z0-9_]{0,39}$")  # a node name (server/runs/spec.py)
# Text has tabs, newlines, carriage returns and form feeds; other C0 control characters (NUL
# above all) mean the file is binary (an image, a spreadsheet) read as text.
_CONTROL = re.compile(r"[\x00-\x08\x0b\x0e-\x1f\x7f]")


class WorkspaceFileError(ValueError):
    """A file the workspace cannot hold; `status` is the HTTP status that fits."""

    def __init__(self, message: str, status: int = 422) -> None:
        super().__init__(message)
        self.status = status


@dataclass(frozen=True, slots=True)
class Caps:
    """The settings that bound a workspace (server/api/settings.py gives the values)."""

    code_bytes: int  # [B] per .py file
    data_bytes: int  # [B] per data file
    workspace_bytes: int  # [B] every file's newest version together
    files: int  # files in one workspace


def file_name(name: str) -> str:
    """The stored name for `name` ("pid" -> "pid.py"); raises WorkspaceFileError."""
    if not name or name != name.strip():
        raise WorkspaceFileError("a file name cannot be empty or start or end with a space")
    if name.startswith("/") or "\\" in name or re.match(r"^[A-Za-z]:", name):
        raise WorkspaceFileError(
            f"'{name}' is an absolute path; give a path inside the workspace, e.g. "
            "'waypoints.csv' or 'config/gains.yaml'"
        )
    parts = name.split("/")
    if any(part in ("", ".", "..") for part in parts):
        raise WorkspaceFileError(
            f"'{name}' has an empty, '.' or '..' part; a file stays inside the workspace"
        )
    if any(part.startswith(".") for part in parts):
        raise WorkspaceFileError(f"'{name}' is a hidden file (its name starts with '.')")
    if len(parts) > MAX_PARTS:
        raise WorkspaceFileError(
            f"'{name}' is {len(parts) - 1} folders deep; at most {MAX_PARTS - 1} are allowed"
        )
    if not all(_PART.match(part) for part in parts):
        raise WorkspaceFileError(
            f"'{name}' may use only letters, digits, '_', '-' and '.' in each part (and '/' "
            "between folders)"
        )
    if "." not in parts[-1]:
        name += CODE_EXTENSION  # a node's name stands for its file, as the page has always sent
    if len(name) > MAX_NAME_CHARS:
        raise WorkspaceFileError(f"'{name}' is longer than {MAX_NAME_CHARS} characters")
    extension = _extension(name)
    if extension == CODE_EXTENSION:
        base = name.rsplit("/", 1)[-1]
        stem = base[: -len(LAUNCH_PY_SUFFIX if is_launch_py(base) else CODE_EXTENSION)]
        if not _NODE_STEM.match(stem):
            raise WorkspaceFileError(
                f"'{name}': a Python file's name is a node name: a letter, then letters, "
                "digits or _ (at most 40), then .py (or .launch.py for a ROS 2 launch file)"
            )
    elif extension not in DATA_EXTENSIONS:
        raise WorkspaceFileError(
            f"'{name}': files ending '{extension}' cannot be kept in a workspace; it holds "
            f"code (.py) and text data files ({', '.join(DATA_EXTENSIONS)})"
        )
    return name


def is_code(name: str) -> bool:
    return _extension(name) == CODE_EXTENSION


def is_launch_py(name: str) -> bool:
    return name.lower().endswith(LAUNCH_PY_SUFFIX)


def is_node_file(name: str) -> bool:
    """A .py file at the top of the workspace (not a .launch.py): a node of a run started
    from the page."""
    return is_code(name) and "/" not in name and not is_launch_py(name)


def check_content(name: str, text: str, caps: Caps) -> None:
    """Raise WorkspaceFileError if `text` is too big or is not text."""
    size = len(text.encode())
    limit = caps.code_bytes if is_code(name) else caps.data_bytes
    if size > limit:
        raise WorkspaceFileError(
            f"'{name}' has {size} bytes; the limit for a {'code' if is_code(name) else 'data'} "
            f"file is {limit} bytes",
            413,
        )
    bad = _CONTROL.search(text)
    if bad is not None:
        line = text.count("\n", 0, bad.start()) + 1
        raise WorkspaceFileError(
            f"'{name}' is not text (control character {ord(bad.group()):#04x} on line {line}); "
            "a workspace keeps text files only: save a spreadsheet as CSV"
        )


def check_fits(name: str, text: str, existing: dict[str, int], caps: Caps) -> None:
    """Raise WorkspaceFileError if saving `name` would pass the workspace's count or size cap;
    `existing` is file name -> bytes of its newest version."""
    if name not in existing and len(existing) >= caps.files:
        raise WorkspaceFileError(f"a workspace holds at most {caps.files} files; delete one first")
    total = sum(size for other, size in existing.items() if other != name) + len(text.encode())
    if total > caps.workspace_bytes:
        raise WorkspaceFileError(
            f"saving '{name}' would make the workspace {total} bytes; the limit is "
            f"{caps.workspace_bytes} bytes: delete a file or make one smaller",
            413,
        )


def data_files(files: Iterable[tuple[str, str]]) -> tuple[tuple[str, bytes], ...]:
    """The (name, bytes) every node of a run finds in its working directory: every file of the
    workspace that is not code, in name order (RunSpec.files)."""
    return tuple((name, text.encode()) for name, text in sorted(files) if not is_code(name))


def _extension(name: str) -> str:
    base = name.rsplit("/", 1)[-1]
    return base[base.rfind(".") :].lower() if "." in base else ""
