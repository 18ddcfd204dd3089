"""std_msgs: ROS 1's basic types (Header, String, Bool, numbers, multi-arrays).

Each class is built on first use from the definitions in ``_definitions.py``.
"""

from ._lazy import install

install(globals(), "std_msgs", ("msg", "srv"))
