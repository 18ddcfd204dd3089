"""sensor_msgs: laser scans, IMU, range, images, camera info, joystick... (ros/common_msgs).

Each class is built on first use from the definitions in ``_definitions.py``.
"""

from ._lazy import install

install(globals(), "sensor_msgs", ("msg", "srv"))
