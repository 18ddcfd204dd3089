"""The bubblewrap command line that walls in one node.

What the node sees:
- read-only: /usr (with the /bin, /lib, /lib64 links), the Python installation running the
  server and the site-packages directories it imports from, /etc/fonts and /etc/ld.so.cache;
  RoboDojo's `sandbox` package at /opt/robodojo/sandbox (and not `server`, nor the rest of the
  checkout, nor the server's data directory: nothing else of the host file system exists);
- writable: a private /tmp and a size-capped scratch directory /home/student (its working
  directory), both tmpfs, gone with the process;
- every namespace unshared (user, pid, net, ipc, uts, cgroup): no network at all, not even
  loopback; it runs as uid/gid 65534 (nobody) with every capability dropped, in a new session,
  and dies with its parent;
- an environment we build (`sandbox_environment`), never a copy of the server's: bwrap itself is
  started with it, not only told to `--clearenv` for its child. bwrap is pid 1 inside and any
  process there may read `/proc/1/environ`, which is the environment bwrap was *started* with
  (clearenv() changes what a process passes on, not that text): started with the server's, it
  gave every student the database and Redis URLs and their passwords. The fresh `/proc` of the
  new pid namespace shows only the sandbox's own processes;
- the stage-1 seccomp filter (sandbox/seccomp.py), read by bwrap from an inherited fd.
"""

from __future__ import annotations

import importlib.util
import os
import shutil
import site
import subprocess
import sys
import sysconfig
from pathlib import Path

import sandbox

SANDBOX_ROOT = "/opt/robodojo"  # where the sandbox package appears inside
FONT_CACHE_DIR = "/opt/robodojo-fonts"  # matplotlib's font list, built once by the launcher
SCRATCH_DIR = "/home/student"  # the node's working directory inside
NOBODY = 65534
TMP_BYTES = 16 * 1024 * 1024  # [bytes] private /tmp (matplotlib's cache lives in scratch)


class SandboxUnavailable(RuntimeError):
    """bubblewrap or user namespaces are missing; the message says how to get them."""


def bwrap_path() -> str | None:
    return shutil.which("bwrap")


def _python_roots() -> list[str]:
    """Directories the interpreter and its packages live in (deduplicated, outermost first)."""
    candidates = {
        sys.prefix,
        sys.base_prefix,
        sys.exec_prefix,
        sysconfig.get_paths()["stdlib"],
        sysconfig.get_paths()["platstdlib"],
        sysconfig.get_paths()["purelib"],
        sysconfig.get_paths()["platlib"],
        *site.getsitepackages(),
    }
    real = sorted({os.path.realpath(path) for path in candidates if os.path.isdir(path)})
    roots: list[str] = []
    for path in real:
        if path.startswith("/usr/"):
            continue  # already visible through /usr
        if not any(path == root or path.startswith(root + os.sep) for root in roots):
            roots.append(path)
    return roots


def _installed_server_dir() -> str | None:
    spec = importlib.util.find_spec("server")
    if spec is None or not spec.submodule_search_locations:
        return None
    return os.path.realpath(next(iter(spec.submodule_search_locations)))


def sandbox_package_dir() -> str:
    return str(Path(sandbox.__file__).resolve().parent)


def build_command(
    seccomp_fd: int,
    scratch_bytes: int,
    runner_args: list[str],
    font_cache: str | None = None,
) -> list[str]:
    """The full argv: bwrap, its options, then the Python runner and `runner_args`."""
    command = walls(scratch_bytes)
    if font_cache:
        command += ["--ro-bind", font_cache, FONT_CACHE_DIR]
    # bwrap is started with this same environment (sandbox_environment); --clearenv and these
    # --setenv make the node's independent of what bwrap was given, should a caller forget.
    for name, value in sandbox_environment(font_cache).items():
        command += ["--setenv", name, value]
    # The root itself is a tmpfs bwrap made; without this a node could fill memory writing to /.
    command += ["--remount-ro", "/"]
    command += ["--seccomp", str(seccomp_fd)]
    command += [sys.executable, "-I", "-S", "-c", runner_bootstrap(SANDBOX_ROOT), *runner_args]
    return command


def walls(
    scratch_bytes: int,
    hostname: str = "robodojo-node",
    proc: bool = True,
    workdir: str = SCRATCH_DIR,
) -> list[str]:
    """bwrap and the options every sandbox shares (the module docstring's list, up to the
    environment, the seccomp filter and the program): a node's, and the editor's analysis
    (sandbox/editor_walls.py: no /proc, another working directory)."""
    bwrap = bwrap_path()
    if bwrap is None:
        raise SandboxUnavailable(
            "bubblewrap (bwrap) is not installed; install the Debian package 'bubblewrap' "
            "(apt-get install bubblewrap) or start the server with --unsafe-no-sandbox"
        )
    command = [
        bwrap,
        "--unshare-all",
        "--unshare-user",
        "--uid", str(NOBODY),
        "--gid", str(NOBODY),
        "--hostname", hostname,
        "--cap-drop", "ALL",
        "--die-with-parent",
        "--new-session",
        "--clearenv",
        "--ro-bind", "/usr", "/usr",
        "--symlink", "usr/bin", "/bin",
        "--symlink", "usr/sbin", "/sbin",  # ctypes finds libseccomp through ldconfig
        "--symlink", "usr/lib", "/lib",
        "--symlink", "usr/lib64", "/lib64",
        "--ro-bind-try", "/etc/fonts", "/etc/fonts",
        "--ro-bind-try", "/etc/ld.so.cache", "/etc/ld.so.cache",
        *(("--proc", "/proc") if proc else ()),
        "--dev", "/dev",
        "--size", str(TMP_BYTES), "--tmpfs", "/tmp",
        "--size", str(scratch_bytes), "--tmpfs", SCRATCH_DIR,
        "--chdir", workdir,
    ]  # fmt: skip
    roots = _python_roots()
    for root in roots:
        command += ["--ro-bind", root, root]
    # A regular (not editable) install puts `server` into site-packages, which is bound above:
    # cover it with an empty directory so student code cannot import the server's code.
    server_dir = _installed_server_dir()
    visible = ["/usr", *roots]  # an install under /usr/local is bound along with /usr
    if server_dir and any(server_dir.startswith(root + os.sep) for root in visible):
        command += ["--tmpfs", server_dir]
    command += ["--ro-bind", sandbox_package_dir(), f"{SANDBOX_ROOT}/sandbox"]
    return command


# PATH inside the sandbox: only /usr is there (/bin links to it). Nothing needs a search path
# (every program is started by its absolute path), but a student's subprocess call would look.
SANDBOX_PATH = "/usr/local/bin:/usr/bin:/bin"


def sandbox_environment(font_cache: str | None = None) -> dict[str, str]:
    """The whole environment of a sandbox: what bwrap is started with (the Popen's `env`, so
    pid 1's /proc/1/environ), and what the node inside gets. Built here from constants, never
    filtered from os.environ: a variable the server has (a password, a database URL) cannot
    reach it, whatever it is called."""
    env = node_environment(SCRATCH_DIR)
    if font_cache:
        env["ROBODOJO_FONT_CACHE"] = FONT_CACHE_DIR
    return env


def node_environment(home: str) -> dict[str, str]:
    """The whole environment of a node with `home` as its home and working directory."""
    return {
        "PATH": SANDBOX_PATH,
        "HOME": home,
        "MPLBACKEND": "Agg",
        "MPLCONFIGDIR": f"{home}/.matplotlib",
        "OPENBLAS_NUM_THREADS": "1",  # one core per node; BLAS threads would steal the other
        "OMP_NUM_THREADS": "1",
        "PYTHONDONTWRITEBYTECODE": "1",
        "PYTHONHASHSEED": "0",  # set iteration order is the same in every run
        "LANG": "C.UTF-8",  # UTF-8 text I/O whatever locale the host has
        "LC_ALL": "C.UTF-8",
    }


def package_paths() -> list[str]:
    """The site-packages directories, and the plain directories their .pth files add, in the
    order `site` would put them on sys.path.

    The runner starts with `python -S` and puts these on the path itself: `site` would also run
    the `import` lines of every .pth file (editable-install finders, certificate hooks), about
    60 ms of each node's start, none of it useful inside the sandbox."""
    paths: list[str] = []
    for sitedir in site.getsitepackages():
        if not os.path.isdir(sitedir):
            continue
        paths.append(sitedir)
        for name in sorted(os.listdir(sitedir)):
            if not name.endswith(".pth"):
                continue
            try:
                lines = Path(sitedir, name).read_text(encoding="utf-8").splitlines()
            except (OSError, UnicodeDecodeError):
                continue
            for line in lines:
                line = line.strip()
                if not line or line.startswith(("#", "import ", "import\t")):
                    continue
                directory = os.path.join(sitedir, line)
                if os.path.isdir(directory) and directory not in paths:
                    paths.append(directory)
    return paths


def runner_bootstrap(root: str) -> str:
    """The `python -I -S -c` program: put the sandbox package, the rospy shim and the installed
    packages on sys.path, give back the `exit()`/`quit()` that `site` would have defined (student
    scripts call them), and start the runner. (-I: no PYTHONPATH, no user site, no current
    directory on the path; -S: no `site`, see `package_paths`.)"""
    return (
        "import sys,site;"
        f"sys.path[:0]=[{root!r},{root + '/sandbox/ros_compat'!r}];"
        f"sys.path+={package_paths()!r};"
        "site.setquit();"
        "from sandbox.runner import main;"
        "raise SystemExit(main(sys.argv[1:]))"
    )


def probe() -> str | None:
    """None when bubblewrap can build a sandbox here, else a sentence saying why not."""
    bwrap = bwrap_path()
    if bwrap is None:
        return "bubblewrap (bwrap) is not installed (Debian package 'bubblewrap')"
    try:
        result = subprocess.run(
            [bwrap, "--unshare-all", "--unshare-user", "--uid", str(NOBODY),
             "--ro-bind", "/usr", "/usr", "--symlink", "usr/lib64", "/lib64",
             "--symlink", "usr/lib", "/lib", "--symlink", "usr/bin", "/bin",
             # A container that masks /proc refuses a fresh one: find that out now, not at
             # every run.
             "--proc", "/proc", "--dev", "/dev",
             "--die-with-parent", "/usr/bin/true"],
            capture_output=True, text=True, timeout=10, env=sandbox_environment(), cwd="/",
        )  # fmt: skip
    except (OSError, subprocess.TimeoutExpired) as error:
        return f"bubblewrap could not start: {error}"
    if result.returncode != 0:
        return (
            "bubblewrap cannot create namespaces here (user namespaces disabled, or a container "
            f"without them): {result.stderr.strip()}"
        )
    return None


def precompile_package() -> bool:
    """Write the bytecode of the sandbox package next to its sources, once, outside any sandbox.

    Nodes see the package read-only and with PYTHONDONTWRITEBYTECODE, so a module without a
    current .pyc is compiled again at every node start (the node host, the rospy shim and the
    message types: tens of milliseconds). Up to date, this is a stat per file. False if the
    directory is not writable (an installed package normally comes compiled)."""
    import compileall

    package = sandbox_package_dir()
    if not os.access(package, os.W_OK):
        return False  # nothing could be written: do not compile it all in vain at every start
    try:
        return bool(compileall.compile_dir(package, quiet=2))
    except OSError:
        return False


def prepare_font_cache(cache_root: str | None = None) -> str | None:
    """Build matplotlib's font list once, outside any sandbox, and return its directory.

    Without it every fresh sandbox scans the system fonts again (about 1 s per node start).
    The list holds absolute font paths, which are the same inside the sandbox (/usr and the
    Python installation are bound at their own paths). None if it cannot be built."""
    root = cache_root or os.path.join(
        os.environ.get("XDG_CACHE_HOME", os.path.expanduser("~/.cache")), "robodojo", "matplotlib"
    )
    os.makedirs(root, exist_ok=True)
    if not any(name.startswith("fontlist") for name in os.listdir(root)):
        subprocess.run(
            [sys.executable, "-I", "-c", "import matplotlib.font_manager"],
            env={**os.environ, "MPLCONFIGDIR": root, "MPLBACKEND": "Agg"},
            capture_output=True,
            timeout=120,
            check=False,
        )
    return root if any(name.startswith("fontlist") for name in os.listdir(root)) else None
