"""`roslib` for old ROS 1 scripts: ``roslib.load_manifest('pkg')`` and ``roslib.message``.

Real roslib's ``load_manifest`` put a package's Python path on ``sys.path`` (before catkin); here
every provided package is already importable, so it does nothing, as it does in noetic for a
catkin package. ``roslib.message`` finds message and service classes by name.
"""

from . import message


def load_manifest(package_name: str, bootstrap_version: str = "0.7") -> None:
    """Does nothing: the message packages are importable without it (kept for old scripts)."""
    del package_name, bootstrap_version


_interactive = False


def set_interactive(interactive: bool) -> None:
    """Remember whether the script runs interactively (as roslib does; nothing reads it here)."""
    global _interactive
    _interactive = bool(interactive)


def is_interactive() -> bool:
    return _interactive


__all__ = ["is_interactive", "load_manifest", "message", "set_interactive"]
