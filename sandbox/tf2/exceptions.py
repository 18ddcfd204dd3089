"""tf2's exceptions (the names and hierarchy of tf2_py, which tf2_ros re-exports): every one is
a TransformException, so `except tf2_ros.TransformException:` catches them all. They are
defined in tf2_py's C module `tf2` in both ROS 1 and ROS 2, so a traceback names them
`tf2.LookupException`; `__module__` says the same here instead of our internal path."""

from __future__ import annotations


class TransformException(Exception):
    """Base of the tf2 errors."""


class ConnectivityException(TransformException):
    """The two frames are in different trees: no chain of transforms joins them."""


class LookupException(TransformException):
    """A frame does not exist in the buffer (or the tree has a loop)."""


class ExtrapolationException(TransformException):
    """The time asked for is outside the transforms the buffer holds."""


class InvalidArgumentException(TransformException):
    """A frame id is empty or starts with '/'."""


class TimeoutException(TransformException):
    """A wait for a transform ran out of time."""


for _exception in (
    TransformException,
    ConnectivityException,
    LookupException,
    ExtrapolationException,
    InvalidArgumentException,
    TimeoutException,
):
    _exception.__module__ = "tf2"
