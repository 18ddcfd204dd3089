"""Memory, process-count and CPU limits per node through cgroups, where the machine offers them.

rlimits cap one process's address space; a memory cgroup caps what the node really uses (page
cache of its tmpfs included) and the pids cgroup caps threads and processes together. Modes, in
the order `detect()` tries them, with `describe()` naming the one in force:

- `ROBODOJO_CGROUP_ROOT` set: cgroup v2 under that writable, delegated directory.
- cgroup v1 `memory` and `pids` hierarchies mounted and writable (as root on the lab machines):
  each node gets `<our own cgroup>/robodojo/<name>` in both hierarchies, and in the `cpu`
  hierarchy too when it is mounted and writable: cpu.cfs_period_us and cpu.cfs_quota_us are the
  v1 spelling of v2's cpu.max (Documentation/scheduler/sched-bwc.rst), one core by default. A v1
  host without a usable `cpu` hierarchy caps a node's CPU by RLIMIT_CPU (its whole life) and its
  threads by pids.max only (issue 33, finding 10: 8 spinning threads took both cores).
- cgroup v2: the cgroup2 mount is found in /proc/self/mountinfo and our own cgroup in
  /proc/self/cgroup (`0::/path`). If that cgroup is delegated to us (systemd `Delegate=yes`, or
  writable) and offers `memory` and `pids`, we obey the "no internal processes" rule of
  Documentation/admin-guide/cgroup-v2.rst (a non-root cgroup that enables controllers for its
  children holds no processes itself): the server's processes move into the leaf `<root>/server`,
  then `+memory +pids (+cpu)` goes into `<root>/cgroup.subtree_control`, and each node gets
  `<root>/node-...` with memory.max, memory.swap.max = 0 (when swap is accounted), pids.max and
  cpu.max ("quota period", sandbox/limits.py). memory.events' `oom_kill` tells a node killed by
  its memory cap.
- otherwise rlimits alone, with one logged warning saying what to configure.

The launcher starts bwrap through a one-line shell that writes its own pid into the groups'
cgroup.procs and then execs, so the node is inside its limits before its first instruction; the
groups are removed when the node is closed.

Tested: v1 enforcement for real on the lab machine (tests/sandbox/test_attacks.py); the v2 path
against a directory laid out like a cgroup2 filesystem (tests/sandbox/test_cgroups.py). v2
enforcement on a real v2 kernel is NOT exercised there, because that machine's memory and pids
controllers are bound to v1 hierarchies and its cgroup2 mount has none.
"""

from __future__ import annotations

import contextlib
import itertools
import logging
import os
import re
import time
from collections.abc import Mapping

from sandbox.limits import Limits

log = logging.getLogger(__name__)

V1_ROOT = "/sys/fs/cgroup"
ROOT_ENV = "ROBODOJO_CGROUP_ROOT"
V2_REQUIRED = ("memory", "pids")  # without these the v2 groups would cap nothing that matters
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
        (the kernel reaps the pid namespace after its init dies), so retry briefly: every
        millisecond, for half a second at most (a run's end waits on this)."""
        for directory in self.directories:
            for _ in range(500):
                try:
                    os.rmdir(directory)
                    break
                except FileNotFoundError:
                    break
                except OSError:
                    time.sleep(0.001)


class NodeCgroupV2(NodeCgroup):
    """One node's v2 group: a single directory for every controller."""

    def oom_killed(self) -> bool:
        try:
            with open(os.path.join(self.directories[0], "memory.events")) as f:
                fields = dict(line.split() for line in f if line.strip())
        except (OSError, ValueError):
            return False
        return int(fields.get("oom_kill", "0")) > 0


class Cgroups:
    """Creates per-node groups under `<own>/robodojo` in the v1 memory and pids hierarchies,
    and the cpu hierarchy when there is one."""

    def __init__(self, bases: dict[str, str]) -> None:
        self.bases = bases  # controller -> directory of our "robodojo" group

    @classmethod
    def detect(cls, root: str = V1_ROOT) -> Cgroups | None:
        bases = {}
        for controller in ("memory", "pids", "cpu"):
            base = _v1_base(root, controller)
            if base is None and controller != "cpu":  # cpu is a bonus; the others are needed
                return None
            if base is not None:
                bases[controller] = base
        return cls(bases)

    def describe(self) -> str:
        names = " and ".join(self.bases)
        cpu = "" if "cpu" in self.bases else "; no cpu hierarchy: CPU capped by RLIMIT_CPU only"
        return f"cgroup v1 ({names} hierarchies: " + ", ".join(self.bases.values()) + f"){cpu}"

    def create(self, limits: Limits) -> NodeCgroup:
        memory_bytes, max_pids = limits.memory_bytes, limits.max_pids
        name = f"node-{os.getpid()}-{next(_counter)}"
        # Memory first: oom_killed() reads directories[0].
        directories = [os.path.join(base, name) for base in self.bases.values()]
        for directory in directories:
            os.makedirs(directory, exist_ok=True)
        group = NodeCgroup(directories)
        memory, pids = (os.path.join(self.bases[c], name) for c in ("memory", "pids"))
        try:
            _write(os.path.join(memory, "memory.limit_in_bytes"), memory_bytes)
            # Same cap on memory + swap where swap accounting exists: no escape into swap.
            with contextlib.suppress(OSError):
                _write(os.path.join(memory, "memory.memsw.limit_in_bytes"), memory_bytes)
            _write(os.path.join(pids, "pids.max"), max_pids)
            if "cpu" in self.bases:
                cpu = os.path.join(self.bases["cpu"], name)
                _write(os.path.join(cpu, "cpu.cfs_period_us"), limits.cpu_period_us)
                _write(os.path.join(cpu, "cpu.cfs_quota_us"), limits.cpu_quota_us)
        except OSError:
            group.remove()
            raise
        return group


def _v1_base(root: str, controller: str) -> str | None:
    """Our writable `robodojo` group in the v1 hierarchy of `controller`, made if missing."""
    own = _own_path(controller)
    mount = os.path.join(root, controller)
    if own is None or not os.path.isdir(mount):
        return None
    base = os.path.join(mount, own.lstrip("/"), "robodojo")
    try:
        os.makedirs(base, exist_ok=True)
    except OSError:
        return None
    return base if os.access(base, os.W_OK) else None


def _write(path: str, value: int | str) -> None:
    with open(path, "w") as f:
        f.write(str(value))


def enter_and_exec(group: NodeCgroup, command: list[str]) -> list[str]:
    """`command`, started through a shell that first moves itself into `group`."""
    joins = "".join(f'echo $$ > "${i + 1}" && ' for i in range(len(group.procs_files)))
    script = f'{joins}shift {len(group.procs_files)} && exec "$@"'
    return ["/bin/sh", "-c", script, "robodojo-node", *group.procs_files, *command]


class CgroupsV2:
    """Per-node groups as children of one delegated cgroup v2 directory."""

    def __init__(self, root: str, controllers: list[str]) -> None:
        self.root = root
        self.controllers = controllers  # enabled in root's cgroup.subtree_control

    @classmethod
    def prepare(cls, root: str) -> CgroupsV2 | str:
        """Take over `root`, or a sentence saying why it cannot be used."""
        try:
            with open(os.path.join(root, "cgroup.controllers")) as f:
                offered = f.read().split()
        except OSError:
            return f"{root} is not a cgroup v2 directory (no cgroup.controllers)"
        missing = [c for c in V2_REQUIRED if c not in offered]
        if missing:
            return f"the cgroup {root} does not offer the {' and '.join(missing)} controller"
        control = os.path.join(root, "cgroup.subtree_control")
        if not (os.access(root, os.W_OK) and os.access(control, os.W_OK)):
            return f"the cgroup {root} is not delegated to this user (not writable)"
        wanted = [c for c in (*V2_REQUIRED, "cpu") if c in offered]
        try:
            _move_into_leaf(root)
            _write(control, " ".join("+" + c for c in wanted))
        except OSError as error:
            return f"cannot enable {', '.join(wanted)} in {control}: {error.strerror or error}"
        return cls(root, wanted)

    def describe(self) -> str:
        files = ["memory.max", "pids.max"] + (["cpu.max"] if "cpu" in self.controllers else [])
        return f"cgroup v2 under {self.root} ({', '.join(files)})"

    def create(self, limits: Limits) -> NodeCgroup:
        directory = os.path.join(self.root, f"node-{os.getpid()}-{next(_counter)}")
        os.makedirs(directory, exist_ok=True)
        group = NodeCgroupV2([directory])
        try:
            _write(os.path.join(directory, "memory.max"), limits.memory_bytes)
            # No escape into swap where swap is accounted (the file exists only then).
            swap = os.path.join(directory, "memory.swap.max")
            if os.path.exists(swap) or os.path.exists(os.path.join(self.root, "memory.swap.max")):
                _write(swap, 0)
            _write(os.path.join(directory, "pids.max"), limits.max_pids)
            if "cpu" in self.controllers:
                cpu_max = f"{limits.cpu_quota_us} {limits.cpu_period_us}"
                _write(os.path.join(directory, "cpu.max"), cpu_max)
        except OSError:
            group.remove()
            raise
        return group


def _move_into_leaf(root: str) -> None:
    """Move the processes in `root` into `root/server` (cgroup-v2.rst "no internal processes").
    The hierarchy's own root is exempt, and has no cgroup.type file: leave it alone."""
    if not os.path.exists(os.path.join(root, "cgroup.type")):
        return
    with open(os.path.join(root, "cgroup.procs")) as f:
        pids = f.read().split()
    if not pids:
        return
    leaf = os.path.join(root, "server")
    os.makedirs(leaf, exist_ok=True)
    for pid in pids:
        with contextlib.suppress(ProcessLookupError):  # it exited meanwhile
            _write(os.path.join(leaf, "cgroup.procs"), pid)


def cgroup2_mount(mountinfo: str) -> tuple[str, str] | None:
    """(root inside the filesystem, mount point) of the first cgroup2 mount in a mountinfo text
    (proc(5): fields 4 and 5, the filesystem type after the " - " separator)."""
    for line in mountinfo.splitlines():
        before, separator, after = line.partition(" - ")
        fields = before.split()
        if separator and len(fields) >= 5 and after.split()[:1] == ["cgroup2"]:
            return _unescape(fields[3]), _unescape(fields[4])
    return None


def own_v2_path(proc_cgroup: str) -> str | None:
    """This process's cgroup v2 path: the `0::/path` line of /proc/self/cgroup."""
    for line in proc_cgroup.splitlines():
        if line.startswith("0::"):
            return line[3:]
    return None


def _unescape(field: str) -> str:
    """mountinfo writes space, tab, newline and backslash as octal escapes (\\040 ...)."""
    return re.sub(r"\\([0-7]{3})", lambda m: chr(int(m.group(1), 8)), field)


def detect_v2(mountinfo: str, proc_cgroup: str) -> CgroupsV2 | None:
    """cgroup v2 in our own cgroup, when it is delegated; else None and the warning."""
    mount, own = cgroup2_mount(mountinfo), own_v2_path(proc_cgroup)
    if mount is None or own is None:
        return _fall_back("no cgroup2 filesystem is mounted and no cgroup v1 memory/pids")
    mount_root, mount_point = mount
    if mount_root != "/" and own.startswith(mount_root):
        own = own[len(mount_root) :]
    result = CgroupsV2.prepare(os.path.join(mount_point, own.lstrip("/")))
    return _fall_back(result) if isinstance(result, str) else result


def detect(environ: Mapping[str, str] = os.environ) -> Cgroups | CgroupsV2 | None:
    """The cgroup mode this machine allows (see the module docstring), or None for rlimits."""
    configured = environ.get(ROOT_ENV)
    if configured:
        result = CgroupsV2.prepare(configured)
        return _fall_back(result) if isinstance(result, str) else result
    v1 = Cgroups.detect()
    if v1 is not None:
        return v1
    try:
        with open("/proc/self/mountinfo") as m, open("/proc/self/cgroup") as c:
            return detect_v2(m.read(), c.read())
    except OSError as error:
        return _fall_back(f"cannot read /proc/self: {error}")


def in_container() -> bool:
    """Docker and podman mark their containers with these files."""
    return os.path.exists("/.dockerenv") or os.path.exists("/run/.containerenv")


def _fall_back(problem: str) -> None:
    where = (
        "give the container a delegated cgroup v2 directory writable by the server's user "
        "and name it in %s (docker/README.md, 'Node limits')"
        if in_container()
        else "run the server as a systemd unit with Delegate=yes, or set %s to a writable "
        "cgroup v2 directory whose cgroup.controllers lists memory and pids"
    )
    log.warning(
        "%s: nodes run with rlimits only (no real memory, process-count or CPU cap). To enforce "
        f"them, {where}.",
        problem,
        ROOT_ENV,
    )
    return None


def describe(groups: Cgroups | CgroupsV2 | None) -> str:
    """Which limit mode is in force, for the server's log and the admin page."""
    return groups.describe() if groups is not None else "rlimits only (no usable cgroup)"
