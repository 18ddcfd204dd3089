"""A robot at rest: zero velocity and LEDs off, the one definition of what "stop" sends.

Sent at every end of a run (backend.py `HardwareRobot.stop`) and to every robot the moment its
rosserial handshake names a command topic, before anything else can be written to it
(rosserial/server.py). The second is the one that matters after a dropped link: the CrowBot's
firmware has no watchdog of its own and holds its last duty, so a robot whose WiFi dropped
mid-run and that reconnected at once drove on into the wall when it was sent nothing (issue
33, finding 3); its run had ended, and the end's zero went to the dead connection.
"""

from __future__ import annotations

from sandbox.msgs import Message

VELOCITY_TYPE = "geometry_msgs/Twist"  # every robot's velocity command (Control, cmd_vel)
LEDS_TOPIC = "Leds"  # the CrowBot's LED topic (firmware)
LEDS_TYPE = "std_msgs/Int32MultiArray"  # [r, g, b], each 0-255
LEDS_OFF = (0, 0, 0)


def rest_message(topic: str, message_class: type[Message]) -> Message | None:
    """What puts `topic` at rest, or None for a topic that has no rest (a buzzer plays a note
    and ends it by itself). Every Twist a robot takes is a velocity: its rest is zero."""
    type_name = getattr(message_class, "_type", "")
    if type_name == VELOCITY_TYPE:
        return message_class()
    if topic == LEDS_TOPIC and type_name == LEDS_TYPE:
        return message_class(data=list(LEDS_OFF))
    return None
