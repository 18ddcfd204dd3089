"""visualization_msgs: markers for drawing in a 3D view (ros/common_msgs).

Each class is built on first use from the definitions in ``_definitions.py``.
"""

from ._lazy import install

install(globals(), "visualization_msgs", ("msg", "srv"))
