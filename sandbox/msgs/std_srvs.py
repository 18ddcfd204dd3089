"""std_srvs: the services Empty, Trigger and SetBool (ros/ros_comm_msgs).

Each class is built on first use from the definitions in ``_definitions.py``.
"""

from ._lazy import install

install(globals(), "std_srvs", ("msg", "srv"))
