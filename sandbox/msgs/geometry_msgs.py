"""geometry_msgs: points, vectors, poses, velocities, transforms (ros/common_msgs).

Each class is built on first use from the definitions in ``_definitions.py``.
"""

from ._lazy import install

install(globals(), "geometry_msgs", ("msg", "srv"))
