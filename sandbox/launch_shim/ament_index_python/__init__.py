"""Stand-in for `ament_index_python`: packages are the workspace's (sandbox/launch2/packages.py)."""

from ament_index_python.packages import (
    PackageNotFoundError,
    get_package_prefix,
    get_package_share_directory,
)

__all__ = ["PackageNotFoundError", "get_package_prefix", "get_package_share_directory"]
