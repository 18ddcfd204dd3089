"""Memory and process-count limits per node through cgroups, where the machine offers them.

rlimits cap one process's address space; a memory cgroup caps what the node really uses (page
cache of its tmpfs included) and the pids cgroup caps threads and processes together. Used when
the cgroup v1 `memory` and `pids` hierarchies are mounted and writable (as root on the lab
machines); otherwise the node runs with rlimits alone and `describe()` says so. cgroup v2 is not
handled yet.

Each node gets `<our own cgroup>/robodojo/<name>` in both hierarchies. The launcher starts bwrap
through a one-line shell that writes its own pid into the groups and then execs, so the node is
inside its limits before its first instruction; the groups are removed when the node is closed.
"""

from __future__ import annotations

import contextlib
import itertools
import os
import time

V1_ROOT = "/sys/fs/cgroup"
_counter = itertools.count()


def _own_path(controller: str) -> str | None:
    """This process's cgroup path in a v1 hierarchy, from /proc/self/cgroup."""
    try:
        with open("/proc/self/cgroup") as lines:
            for line in lines:
                _, controllers, path = line.rstrip("\n").split(":", 2)
                if controller in controllers.split(","):
                    return path
    except OSError:
        return None
    return None


class NodeCgroup:
    """One node's groups; `procs_files` are what the start-up shell writes its pid into."""

    def __init__(self, directories: list[str]) -> None:
        self.directories = directories
        self.procs_files = [os.path.join(d, "cgroup.procs") for d in directories]

    def oom_killed(self) -> bool:
        """True when the memory controller killed a process of this group."""
        try:
            with open(os.path.join(self.directories[0], "memory.oom_control")) as f:
                fields = dict(line.split() for line in f if line.strip())
        except (OSError, ValueError):
            return False
        return int(fields.get("oom_kill", "0")) > 0

    def remove(self) -> None:
        """Delete the groups. A killed node's processes take a few milliseconds to leave them
        (the kernel reaps the pid namespace after its init dies), so retry briefly."""
        for directory in self.directories:
            for _ in range(50):
                try:
                    os.rmdir(directory)
                    break
                except FileNotFoundError:
                    break
                except OSError:
                    time.sleep(0.01)


class Cgroups:
    """Creates per-node groups under `<own>/robodojo` in the v1 memory and pids hierarchies."""

    def __init__(self, bases: dict[str, str]) -> None:
        self.bases = bases  # controller -> directory of our "robodojo" group

    @classmethod
    def detect(cls) -> Cgroups | None:
        bases = {}
        for controller in ("memory", "pids"):
            own = _own_path(controller)
            mount = os.path.join(V1_ROOT, controller)
            if own is None or not os.path.isdir(mount):
                return None
            base = os.path.join(mount, own.lstrip("/"), "robodojo")
            try:
                os.makedirs(base, exist_ok=True)
            except OSError:
                return None
            if not os.access(base, os.W_OK):
                return None
            bases[controller] = base
        return cls(bases)

    def create(self, memory_bytes: int, max_pids: int) -> NodeCgroup:
        name = f"node-{os.getpid()}-{next(_counter)}"
        memory = os.path.join(self.bases["memory"], name)
        pids = os.path.join(self.bases["pids"], name)
        os.makedirs(memory, exist_ok=True)
        os.makedirs(pids, exist_ok=True)
        group = NodeCgroup([memory, pids])
        try:
            _write(os.path.join(memory, "memory.limit_in_bytes"), memory_bytes)
            # Same cap on memory + swap where swap accounting exists: no escape into swap.
            with contextlib.suppress(OSError):
                _write(os.path.join(memory, "memory.memsw.limit_in_bytes"), memory_bytes)
            _write(os.path.join(pids, "pids.max"), max_pids)
        except OSError:
            group.remove()
            raise
        return group


def _write(path: str, value: int) -> None:
    with open(path, "w") as f:
        f.write(str(value))


def enter_and_exec(group: NodeCgroup, command: list[str]) -> list[str]:
    """`command`, started through a shell that first moves itself into `group`."""
    joins = "".join(f'echo $$ > "${i + 1}" && ' for i in range(len(group.procs_files)))
    script = f'{joins}shift {len(group.procs_files)} && exec "$@"'
    return ["/bin/sh", "-c", script, "robodojo-node", *group.procs_files, *command]
