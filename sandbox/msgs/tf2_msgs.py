"""tf2_msgs: the transform tree message on /tf, the LookupTransform action (ros/geometry2).

Each class is built on first use from the definitions in ``_definitions.py``.
"""

from ._lazy import install

install(globals(), "tf2_msgs", ("msg", "srv"))
