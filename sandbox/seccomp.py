"""Seccomp filters for sandboxed nodes, in two stages (libseccomp through pyseccomp).

Stage 1 (`write_stage1_bpf`) is handed to bubblewrap (`--seccomp FD`), which installs it before
it executes the runner: it denies the system calls no controller needs and that widen the attack
surface of the kernel (sockets, tracing, mounting, namespaces, BPF, keyrings, perf, module
loading, ...). bubblewrap installs it right before its own execve, so stage 1 cannot block
execve or fork.

Stage 2 (`install_stage2`) is loaded by the runner itself after its imports and before it runs
any student code: it denies creating processes (fork, vfork, clone without CLONE_THREAD,
clone3) and executing programs (execve, execveat). Threads stay allowed (clone with
CLONE_THREAD): numpy's BLAS and matplotlib may start them.

Denied calls fail with EPERM rather than killing the process, so student code gets a Python
exception (PermissionError) it can read, and the node reports it like any other error.
"""

from __future__ import annotations

import errno
from typing import BinaryIO

import pyseccomp as seccomp

# Stage 1: each of these has no use in a controller and a history of kernel exploits or of
# escaping a sandbox (namespace and mount tricks, ptrace of a neighbour, raw network).
STAGE1_DENIED = (
    "socket",  # no network at all, not even AF_UNIX to a server socket bound in by mistake
    "socketpair",
    "ptrace",
    "process_vm_readv",
    "process_vm_writev",
    "mount",
    "umount2",
    "pivot_root",
    "chroot",
    "unshare",
    "setns",
    "bpf",
    "keyctl",
    "add_key",
    "request_key",
    "perf_event_open",
    "userfaultfd",
    "kexec_load",
    "kexec_file_load",
    "init_module",
    "finit_module",
    "delete_module",
    "reboot",
    "swapon",
    "swapoff",
    "acct",
    "settimeofday",
    "clock_settime",
    "clock_adjtime",
    "adjtimex",
    "open_by_handle_at",
    "name_to_handle_at",
    "io_uring_setup",
    "io_uring_enter",
    "io_uring_register",
    "fanotify_init",
    "quotactl",
    "personality",
    "syslog",
    "vhangup",
    "mknod",
    "mknodat",
)

# Stage 2: no new processes, no new programs.
STAGE2_DENIED = ("fork", "vfork", "execve", "execveat")
_CLONE_THREAD = 0x00010000  # linux/sched.h


def _filter(denied: tuple[str, ...]) -> seccomp.SyscallFilter:
    rules = seccomp.SyscallFilter(defaction=seccomp.ALLOW)
    for name in denied:
        rules.add_rule(seccomp.ERRNO(errno.EPERM), name)
    return rules


def write_stage1_bpf(out: BinaryIO) -> None:
    """Write the stage-1 filter as a BPF program (what `bwrap --seccomp FD` reads)."""
    _filter(STAGE1_DENIED).export_bpf(out)


def install_stage2() -> None:
    """Deny fork/exec in this process from now on (and in its threads)."""
    rules = _filter(STAGE2_DENIED)
    # clone(flags, ...) is how both threads and processes start; only threads may.
    rules.add_rule(
        seccomp.ERRNO(errno.EPERM), "clone", seccomp.Arg(0, seccomp.MASKED_EQ, _CLONE_THREAD, 0)
    )
    # clone3 passes its flags in a struct that seccomp cannot read; ENOSYS makes glibc fall
    # back to clone() for threads, which the rule above then checks.
    rules.add_rule(seccomp.ERRNO(errno.ENOSYS), "clone3")
    rules.load()
