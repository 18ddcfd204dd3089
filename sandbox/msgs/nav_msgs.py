"""nav_msgs: odometry, occupancy grid maps, paths; the GetMap action and map services.

Each class is built on first use from the definitions in ``_definitions.py``.
"""

from ._lazy import install

install(globals(), "nav_msgs", ("msg", "srv"))
