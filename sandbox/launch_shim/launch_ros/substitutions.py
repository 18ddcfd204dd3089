"""Stand-in for `launch_ros.substitutions`."""

from sandbox.launch2.missing import missing
from sandbox.launch2.substitutions import FindPackage, FindPackagePrefix, FindPackageShare

__all__ = ["FindPackage", "FindPackagePrefix", "FindPackageShare"]
__getattr__ = missing("launch_ros.substitutions")
