"""ROS 2 Jazzy interfaces that rosbags' type store does not carry, as ``.msg``/``.srv`` text.

Field lists from the interface files (see ``_generate.py``); read by ``_generate.py`` only.
"""

from __future__ import annotations

EXTRA_MESSAGES: dict[str, str] = {}
SERVICES: dict[str, tuple[str, str]] = {}
ACTIONS: dict[str, tuple[str, str, str]] = {}
