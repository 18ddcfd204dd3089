"""The walls of the editor's analysis (sandbox/editor_walls.py), tried from inside: what the
host's sandbox shows (nothing of the server but its analysis code, no /proc, an empty read-only
project folder), and what a sealed request's process may still do (read; write to the pipes it
holds; within its memory cap; nothing else: no file written, no process or program started,
no signal to another process). Each probe runs in a Python of its own and reports as JSON."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest

from sandbox import bwrap, editor_walls
from sandbox.seccomp import write_stage1_bpf
from server.editor.ruff_tool import ruff_binary

REPO = Path(__file__).resolve().parents[2]
RUN_S = 60.0  # [s] a probe's Python start and its look around, on a loaded machine

needs_bwrap = pytest.mark.skipif(bwrap.probe() is not None, reason=f"no sandbox: {bwrap.probe()}")

LOOK_AROUND = """
import json, os
def listing(path):
    try:
        return sorted(os.listdir(path))
    except OSError as error:
        return type(error).__name__
def writes(path):
    try:
        with open(path, "w") as out:
            out.write("x")
        return True
    except OSError:
        return False
print(json.dumps({
    "root": listing("/"),
    "proc": os.path.exists("/proc/self"),
    "project": listing(%(project)r),
    "server": listing(%(server)r),
    "checkout": [p for p in %(checkout)r if os.path.exists(p)],
    "stub write": writes(%(stub)r + "/x"),
    "project write": writes(%(project)r + "/x"),
    "cache write": writes(%(cache)r + "/x"),
    "uid": os.getuid(),
    "environ": sorted(os.environ),
}))
"""


@needs_bwrap
def test_the_hosts_sandbox_shows_nothing_of_the_server(tmp_path):
    stubs, cache = tmp_path / "stubs", tmp_path / "cache"
    stubs.mkdir()
    cache.mkdir()
    checkout = [str(REPO / name) for name in ("server/api", "server/store", "pyproject.toml",
                                             "sandbox/launcher.py", "tests")]  # fmt: skip
    code = LOOK_AROUND % {"project": editor_walls.PROJECT_DIR, "stub": editor_walls.STUB_DIR,
                          "cache": editor_walls.CACHE_DIR, "checkout": checkout,
                          "server": f"{editor_walls.EDITOR_ROOT}/server"}  # fmt: skip
    with tempfile.TemporaryFile() as bpf:
        write_stage1_bpf(bpf)
        bpf.seek(0)
        seccomp_fd = os.dup(bpf.fileno())
    command = editor_walls.build_command(
        seccomp_fd, str(REPO / "server" / "editor"), str(stubs), str(cache),
        os.path.realpath(ruff_binary()), [sys.executable, "-I", "-S", "-c", code],
    )  # fmt: skip
    try:
        done = subprocess.run(
            command,
            capture_output=True,
            text=True,
            timeout=RUN_S,
            pass_fds=(seccomp_fd,),
            env=bwrap.sandbox_environment(),
            cwd="/",
        )
    finally:
        os.close(seccomp_fd)
    assert done.returncode == 0, done.stderr
    seen = json.loads(done.stdout)
    assert "proc" not in seen["root"] and not seen["proc"]
    assert seen["project"] == []
    assert seen["server"] == ["editor"]  # the analysis code, and not the rest of the server
    assert seen["checkout"] == []
    assert not seen["stub write"] and not seen["project write"]
    assert seen["cache write"]  # the host's own (a request's process cannot: below)
    assert seen["uid"] == bwrap.NOBODY
    # What we built, and the working folder bwrap sets.
    assert seen["environ"] == sorted([*bwrap.sandbox_environment(), "PWD"])


SEALED = """
import json, os, sys, threading
sys.path[:0] = [%(repo)r]
from sandbox.editor_walls import seal_request
readable = open(%(readable)r).read()
parent = os.getppid()
seal_request(runs_program=%(program)r)
def attempt(action):
    try:
        action()
        return "done"
    except Exception as error:
        return type(error).__name__
def start_thread():
    thread = threading.Thread(target=lambda: None)
    thread.start()
    thread.join()
tried = {
    "read": attempt(lambda: open(%(readable)r).read()),
    "create": attempt(lambda: open(%(folder)r + "/new", "w")),
    "append": attempt(lambda: open(%(readable)r, "a")),
    "remove": attempt(lambda: os.unlink(%(readable)r)),
    "rename": attempt(lambda: os.rename(%(readable)r, %(folder)r + "/moved")),
    "mkdir": attempt(lambda: os.mkdir(%(folder)r + "/dir")),
    "fork": attempt(os.fork),
    "thread": attempt(start_thread),
    "signal the parent": attempt(lambda: os.kill(parent, 0)),
    "signal itself": attempt(lambda: os.kill(os.getpid(), 0)),
    "pipe": attempt(lambda: os.write(1, b"")),
}
print(json.dumps(tried), flush=True)
if %(program)r:
    os.execv("/bin/true", ["true"])
"""


@pytest.mark.parametrize("program", [False, True], ids=["analysis", "ruff"])
def test_a_sealed_request_reads_and_writes_its_pipe_and_nothing_else(tmp_path, program):
    readable = tmp_path / "library.py"
    readable.write_text("x = 1\n")
    code = SEALED % {"repo": str(REPO), "readable": str(readable), "folder": str(tmp_path),
                     "program": program}  # fmt: skip
    done = subprocess.run([sys.executable, "-I", "-c", code], capture_output=True, text=True,
                          timeout=RUN_S)  # fmt: skip
    assert done.returncode == 0, done.stderr
    tried = json.loads(done.stdout.splitlines()[0])
    assert tried["read"] == tried["signal itself"] == tried["pipe"] == "done"
    for action in ("create", "append", "remove", "rename", "mkdir", "fork", "signal the parent"):
        assert tried[action] == "PermissionError", (action, tried)
    # One thread and no program for an analysis; ruff's process runs ruff and its threads.
    assert tried["thread"] == ("done" if program else "RuntimeError")
    assert readable.read_text() == "x = 1\n" and sorted(os.listdir(tmp_path)) == ["library.py"]


MEMORY = """
import sys
sys.path[:0] = [%(repo)r]
from sandbox.editor_walls import limit_request
from server.editor.request import _mapped_bytes
limit_request(_mapped_bytes() + 32 * 1024 * 1024, 10, 64)
small = bytearray(8 * 1024 * 1024)
try:
    large = bytearray(64 * 1024 * 1024)
    print("allocated")
except MemoryError:
    print("MemoryError")
"""


def test_a_request_has_its_memory_beyond_what_it_inherits_and_no_more():
    done = subprocess.run([sys.executable, "-I", "-c", MEMORY % {"repo": str(REPO)}],
                          capture_output=True, text=True, timeout=RUN_S)  # fmt: skip
    assert done.stdout.strip() == "MemoryError", done.stderr
