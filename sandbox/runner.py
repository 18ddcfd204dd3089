"""The child side of a sandboxed node: the program bubblewrap starts.

Runs inside the sandbox (see sandbox/launcher.py for the walls). In order:
1. lower its own rlimits to the values the launcher passed, and its priority (`nice`), before
   any import (so the imports count against the address-space cap);
2. import the node host (the message types, the rospy shim: light), and, in a process meant for
   the warm pool only (`preload` in the settings), what controllers use too (numpy, matplotlib
   with the Agg backend, scipy, scikit-fuzzy, rclpy) and the classes of the robots' message
   types (`message_types`), so a node taken from the pool starts at once. A node started cold
   skips those (about 1 s of imports): the student's own `import` loads them, in the sealed
   process, as any other module;
3. seal itself: the stage-2 seccomp filter (no fork, no exec) goes on here, after the imports
   and before any student code;
4. send Ready and wait for Load; run the node (sandbox.host) and send what it returns.

Frames go over the inherited fds the launcher names in the settings; fd 1 and 2 are the log
stream.
"""

from __future__ import annotations

import json
import os
import resource
import sys
import time

_RLIMITS = {
    "address_space_bytes": resource.RLIMIT_AS,
    "cpu_seconds": resource.RLIMIT_CPU,
    "open_files": resource.RLIMIT_NOFILE,
    "file_size_bytes": resource.RLIMIT_FSIZE,
}


def _apply_rlimits(limits: dict[str, int]) -> None:
    for name, which in _RLIMITS.items():
        if name in limits:
            value = int(limits[name])
            resource.setrlimit(which, (value, value))
    # No core dumps: a crashing node must not write its memory to the scratch directory.
    resource.setrlimit(resource.RLIMIT_CORE, (0, 0))


def _seed_font_cache() -> None:
    """Copy the launcher's prebuilt matplotlib font list into this node's config directory."""
    source = os.environ.get("ROBODOJO_FONT_CACHE")
    target = os.environ.get("MPLCONFIGDIR")
    if not (source and target and os.path.isdir(source)):
        return
    import shutil

    os.makedirs(target, exist_ok=True)
    for name in os.listdir(source):
        if name.startswith("fontlist") and name.endswith(".json"):
            shutil.copyfile(os.path.join(source, name), os.path.join(target, name))


def _host_imports() -> None:
    """What every node needs before it says Ready: the node host and the ROS 1 message types."""
    import sandbox.host
    import sandbox.msgs  # noqa: F401


def _warm_imports() -> None:
    """The heavy libraries controllers use, for a process that will wait in the warm pool."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot
    import numpy  # noqa: F401
    import scipy  # noqa: F401
    import skfuzzy  # noqa: F401

    _warm_rclpy()


def _warm_rclpy() -> None:
    """rclpy and the ROS 2 types, imported ahead like the rest (about 0.2 s a node would
    otherwise spend at its first `import rclpy`). The path entry and the modules go again at
    once: the host puts each dialect's layer on sys.path for its node, and the modules set
    aside here back into sys.modules for a ROS 2 node only."""
    import sandbox.msgs2  # noqa: F401
    from sandbox.host import ROS_COMPAT2_DIR, set_aside_modules_from

    sys.path.insert(0, ROS_COMPAT2_DIR)
    try:
        import rclpy.executors
        import rclpy.node  # noqa: F401
    finally:
        sys.path.remove(ROS_COMPAT2_DIR)
        set_aside_modules_from(ROS_COMPAT2_DIR)


class PipeLink:
    """The node host's view of the parent: whole frames over the protocol pipes."""

    def __init__(self, fd_in: int, fd_out: int) -> None:
        from sandbox.protocol import FrameReader, FrameWriter, ToChild

        self._reader = FrameReader(fd_in, ToChild)
        self._writer = FrameWriter(fd_out)

    def send(self, frame: object) -> None:
        self._writer.send(frame)

    def receive(self) -> object:
        return self._reader.receive()


def main(argv: list[str] | None = None) -> int:
    started = time.perf_counter()
    args = argv if argv is not None else sys.argv[1:]
    settings = json.loads(args[0]) if args else {}
    _apply_rlimits(settings.get("rlimits", {}))
    os.nice(int(settings.get("nice", 0)))  # lower priority only: allowed without privileges
    _seed_font_cache()  # before any matplotlib import, ours or the student's
    _host_imports()
    if settings.get("preload", True):
        _warm_imports()
        from sandbox.msgs2.bridge import build_both_dialects

        build_both_dialects(settings.get("message_types", []))
    if settings.get("seal", True):
        from sandbox.seccomp import install_stage2

        install_stage2()

    from sandbox.host import run_node
    from sandbox.protocol import Exited, Load, Outcome, ProtocolError, Ready

    link = PipeLink(settings["fd_in"], settings["fd_out"])
    link.send(
        Ready(
            pid=os.getpid(),
            python=sys.version.split()[0],
            startup_ms=(time.perf_counter() - started) * 1000.0,
        )
    )
    try:
        load = link.receive()
    except ProtocolError:
        return 0  # the pool closed before this process was used
    if not isinstance(load, Load):
        return 0  # Shutdown while idle in the pool
    try:
        exited = run_node(link, load, os.getcwd())
    except ProtocolError:
        return 0  # the parent went away mid-run; nothing left to tell it
    except BaseException as error:  # a bug of ours, not the student's: say so, briefly
        exited = Exited(
            outcome=Outcome.CRASHED, reason=f"internal error in the node host: {error!r}"
        )
    sys.stdout.flush()
    sys.stderr.flush()
    link.send(exited)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
