"""The walls of the editor's analysis: what its host process (server/editor/host.py) sees, and
what each request's process may do once it holds a student's text.

The host lives inside a node's walls (sandbox/bwrap.py `walls`: every namespace unshared, no
network, uid nobody, no capabilities, the stage-1 seccomp filter, an environment built from
constants), without /proc, and sees besides /usr and the Python installation only:

- /opt/robodojo/sandbox: the `sandbox` package (the source of rospy, rclpy and the message
  types that jedi reads);
- /opt/robodojo-editor/server/editor: the analysis code itself, not the rest of the server;
- /opt/robodojo-editor/stubs: the message stubs the server wrote, read-only;
- /opt/robodojo-editor/cache: jedi's parse cache, written by the host only (see below);
- /opt/robodojo-editor/bin/ruff: the ruff program;
- /opt/robodojo-editor/project: empty and read-only, the one folder jedi completes file names in.

No /proc: a request's process has no file through which to read another's memory.

Each request is answered by a process forked from the host, which first limits itself
(`limit_request`: address space, CPU seconds, open files, no core file) and then seals itself
(`seal_request`): from then on it can read what the walls show and write only to the pipes it
holds. No file is opened for writing, created, renamed or removed (so nothing a request does
can be found by the next one, whoever asks it), no process is started and no program run
(ruff's process runs ruff, once, and ruff may start threads), no signal reaches another
process (the host, or a neighbour answering someone else).
"""

from __future__ import annotations

import errno
import os
import resource
import sys

# Imported here, by the host, once: in a request's process the import alone cost ~20 ms.
import pyseccomp as seccomp

from sandbox import bwrap

EDITOR_ROOT = "/opt/robodojo-editor"  # where the editor's own files appear inside
CODE_DIR = f"{EDITOR_ROOT}/server/editor"
STUB_DIR = f"{EDITOR_ROOT}/stubs"
CACHE_DIR = f"{EDITOR_ROOT}/cache"
RUFF = f"{EDITOR_ROOT}/bin/ruff"
PROJECT_DIR = f"{EDITOR_ROOT}/project"
LIBRARY_ROOT = bwrap.SANDBOX_ROOT  # holds `sandbox` and nothing else: jedi's view of it
# Scratch tmpfs the shared walls mount [bytes]: the analysis writes nothing (its requests
# cannot, the host only to the cache), so it stays small.
SCRATCH_BYTES = 1024 * 1024

# What a sealed request may not do to a file (besides opening one for writing).
_FILE_CHANGES = (
    "creat", "truncate", "rename", "renameat", "renameat2", "unlink", "unlinkat", "mkdir",
    "mkdirat", "rmdir", "link", "linkat", "symlink", "symlinkat", "chmod", "fchmod", "fchmodat",
    "chown", "fchown", "lchown", "fchownat", "utime", "utimes", "utimensat", "futimesat",
    "setxattr", "lsetxattr", "fsetxattr", "removexattr", "lremovexattr", "fremovexattr",
)  # fmt: skip
_OPEN_FOR_WRITING = (os.O_WRONLY, os.O_RDWR, os.O_CREAT, os.O_TRUNC)
# Signals to others, and handles on other processes.
_OTHER_PROCESSES = ("tkill", "rt_sigqueueinfo", "rt_tgsigqueueinfo", "pidfd_open",
                    "pidfd_send_signal", "pidfd_getfd")  # fmt: skip
_CLONE_THREAD = 0x00010000  # linux/sched.h


def build_command(
    seccomp_fd: int, code_dir: str, stub_dir: str, cache_dir: str, ruff: str, program: list[str]
) -> list[str]:
    """bwrap with the walls above, then `program` (a Python started as `python_program` says)."""
    command = bwrap.walls(SCRATCH_BYTES, "robodojo-editor", proc=False, workdir=PROJECT_DIR)
    command += [
        "--ro-bind", code_dir, CODE_DIR,
        "--ro-bind", stub_dir, STUB_DIR,
        "--bind", cache_dir, CACHE_DIR,
        "--ro-bind", ruff, RUFF,
        "--dir", PROJECT_DIR,
    ]  # fmt: skip
    for name, value in bwrap.sandbox_environment().items():
        command += ["--setenv", name, value]
    command += ["--remount-ro", "/", "--seccomp", str(seccomp_fd)]
    return command + program


def python_program(entry_module: str, code_roots: list[str]) -> list[str]:
    """`python -I -S -c ...` running `entry_module`'s main(argv) with `code_roots` first on
    sys.path (inside: EDITOR_ROOT and LIBRARY_ROOT), then the installed packages
    (bwrap.package_paths says why not `site`)."""
    bootstrap = (
        "import sys;"
        f"sys.path[:0]={code_roots!r};"
        f"sys.path+={bwrap.package_paths()!r};"
        f"from {entry_module} import main;"
        "raise SystemExit(main(sys.argv[1:]))"
    )
    return [sys.executable, "-I", "-S", "-c", bootstrap]


def library_roots(inside: bool) -> list[str]:
    """The folders of the libraries jedi reads (the sandbox package, /usr, the Python
    installation), as the host sees them: `inside` the walls or, unsandboxed, outside."""
    package = f"{LIBRARY_ROOT}/sandbox" if inside else bwrap.sandbox_package_dir()
    return [package, "/usr", *bwrap._python_roots()]


def limit_request(
    address_space_bytes: int, cpu_seconds: int, open_files: int, cpu_life_seconds: int = 0
) -> None:
    """A request's rlimits: soft and hard equal, so a request cannot raise them again (CPU:
    SIGXCPU at `cpu_seconds`, SIGKILL a second later). A process that answers several requests
    (a student's, server/editor/host.py) moves its CPU limit on before each, up to
    `cpu_life_seconds` for its whole life (`next_cpu_limit`)."""
    resource.setrlimit(resource.RLIMIT_CORE, (0, 0))  # a crash leaves no file, anywhere
    resource.setrlimit(resource.RLIMIT_NOFILE, (open_files, open_files))
    hard = max(cpu_life_seconds, cpu_seconds + 1)
    resource.setrlimit(resource.RLIMIT_CPU, (cpu_seconds, hard))
    resource.setrlimit(resource.RLIMIT_AS, (address_space_bytes, address_space_bytes))


def next_cpu_limit(cpu_seconds: int) -> None:
    """`cpu_seconds` more of CPU from now on (within the life's hard limit)."""
    used = resource.getrusage(resource.RUSAGE_SELF)
    _, hard = resource.getrlimit(resource.RLIMIT_CPU)
    soft = int(used.ru_utime + used.ru_stime) + cpu_seconds
    resource.setrlimit(resource.RLIMIT_CPU, (min(soft, hard), hard))


def seal_request(runs_program: bool) -> None:
    """The request's seccomp filter (module docstring). `runs_program`: the process is about to
    exec ruff, which may start threads; otherwise it is one thread and stays so."""
    deny = seccomp.ERRNO(errno.EPERM)
    rules = seccomp.SyscallFilter(defaction=seccomp.ALLOW)
    for flag in _OPEN_FOR_WRITING:
        rules.add_rule(deny, "open", seccomp.Arg(1, seccomp.MASKED_EQ, flag, flag))
        rules.add_rule(deny, "openat", seccomp.Arg(2, seccomp.MASKED_EQ, flag, flag))
    # openat2 passes its flags in a struct seccomp cannot read; ENOSYS makes callers fall back
    # to openat, which the rules above check.
    rules.add_rule(seccomp.ERRNO(errno.ENOSYS), "openat2")
    for name in (*_FILE_CHANGES, "fork", "vfork", "execveat", *_OTHER_PROCESSES):
        rules.add_rule(deny, name)
    own = os.getpid()
    rules.add_rule(deny, "kill", seccomp.Arg(0, seccomp.NE, own))
    rules.add_rule(deny, "tgkill", seccomp.Arg(0, seccomp.NE, own))
    # clone3's flags are in a struct too; ENOSYS makes glibc fall back to clone() for threads.
    rules.add_rule(seccomp.ERRNO(errno.ENOSYS), "clone3")
    if runs_program:
        rules.add_rule(deny, "clone", seccomp.Arg(0, seccomp.MASKED_EQ, _CLONE_THREAD, 0))
    else:
        rules.add_rule(deny, "clone")
        rules.add_rule(deny, "execve")
    rules.load()
