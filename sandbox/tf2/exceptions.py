"""tf2's exceptions (the names and hierarchy of tf2_py, which tf2_ros re-exports): every one is
a TransformException, so `except tf2_ros.TransformException:` catches them all."""

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
