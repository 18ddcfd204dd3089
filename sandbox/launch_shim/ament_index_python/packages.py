"""Stand-in for `ament_index_python.packages`."""

from sandbox.launch2.errors import PackageNotFoundError, caller_site
from sandbox.launch2.missing import missing
from sandbox.launch2.packages import get_package_prefix as _prefix
from sandbox.launch2.packages import get_package_share_directory as _share


def get_package_share_directory(package_name: str, print_warning: bool = True) -> str:
    return _share(package_name, caller_site())


def get_package_prefix(package_name: str) -> str:
    return _prefix(package_name, caller_site())


__all__ = ["PackageNotFoundError", "get_package_prefix", "get_package_share_directory"]
__getattr__ = missing("ament_index_python.packages")
