"""tf2's BufferCore: the frame tree over time, and lookups between any two frames in it.

Behaviour as tf2 (ros/geometry2: tf2/src/buffer_core.cpp, exposed to Python by tf2_py):
- set_transform strips a leading '/' from frame ids and ignores (with tf2's logged sentence) a
  transform to itself, an empty frame id, NaN values, or a quaternion whose squared norm is
  more than 0.01 from 1.
- A lookup walks from the source frame up to the root, then from the target frame up until the
  two walks meet; time 0 means "the latest time at which every transform of that chain is
  known" (get_latest_common_time).
- Errors carry tf2's sentences: LookupException for a frame that does not exist (here followed
  by the frames that do), ConnectivityException for frames in different trees,
  ExtrapolationException for a time outside the cache, InvalidArgumentException for an empty
  frame id or one starting with '/'.
The core is pure: no rospy or rclpy, no waiting; each dialect's tf2_ros.Buffer adds those.
Times are the dialect's objects outside (sandbox/tf2/dialect.py: rospy.Time in ROS 1, rclpy or
builtin_interfaces times in ROS 2) and integer nanoseconds inside. One core serves both
sandbox/ros_compat/tf2_ros and sandbox/ros_compat2/tf2_ros.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

from sandbox.msgs import get_message_class

from . import _math
from .dialect import ROS1, Dialect
from .exceptions import (
    ConnectivityException,
    ExtrapolationException,
    InvalidArgumentException,
    LookupException,
    TransformException,
)
from .time_cache import NS_PER_S, StaticCache, Stored, TimeCache

DEFAULT_CACHE_TIME_S = 10.0  # [s] tf2::BufferCore::DEFAULT_CACHE_TIME
MAX_GRAPH_DEPTH = 1000  # tf2's bound on a walk; deeper means the "tree" has a loop
QUATERNION_NORMALIZATION_TOLERANCE = 10e-3  # [1] tf2's bound on |x^2+y^2+z^2+w^2 - 1|
_NO_PARENT = "NO_PARENT"

# Outcomes of a walk, as tf2_msgs/TF2Error codes.
_OK, _LOOKUP, _CONNECTIVITY, _EXTRAPOLATION = 0, 1, 2, 3
_RAISE = {
    _LOOKUP: LookupException,
    _CONNECTIVITY: ConnectivityException,
    _EXTRAPOLATION: ExtrapolationException,
}


def to_nsec(value: Any, what: str) -> int:
    """Integer nanoseconds of a rospy.Time or rospy.Duration (the ROS 1 dialect's reading)."""
    return ROS1.to_nsec(value, what)


def _strip_slash(frame_id: str) -> str:
    return frame_id[1:] if frame_id.startswith("/") else frame_id


def _pose_of(transform: Any) -> _math.Pose:
    t, r = transform.translation, transform.rotation
    return (
        (float(t.x), float(t.y), float(t.z)),
        (float(r.x), float(r.y), float(r.z), float(r.w)),
    )


class BufferCore:
    """Transforms between frames over the last `cache_time` (a Duration; 10 s)."""

    dialect: Dialect = ROS1  # a ROS 2 buffer sets the ROS 2 one

    def __init__(self, cache_time: Any = None) -> None:
        if cache_time is None:
            self._cache_ns = round(DEFAULT_CACHE_TIME_S * NS_PER_S)
        else:
            self._cache_ns = self.dialect.to_nsec(cache_time, "Buffer(cache_time=...)")
        self._frames: dict[str, None] = {}  # every frame name seen, in order (child or parent)
        self._caches: dict[str, TimeCache | StaticCache] = {}
        self._authority: dict[str, str] = {}
        self._reported: set[tuple[str, str]] = set()
        # Where set_transform's complaints go: (level, text); tf2_ros.Buffer points it at the
        # node's log. A pure BufferCore keeps them in `problems` for the caller to read.
        self.problems: list[str] = []
        self.log: Callable[[str, str], None] = lambda level, text: self.problems.append(text)

    # ------------------------------------------------------------------ filling
    def set_transform(self, transform: Any, authority: str = "default_authority") -> bool:
        """Add a geometry_msgs/TransformStamped; False (and a logged reason) if refused."""
        return self._set(transform, authority, static=False)

    def set_transform_static(self, transform: Any, authority: str = "default_authority") -> bool:
        """Add a transform that holds at every time (what arrives on tf_static)."""
        return self._set(transform, authority, static=True)

    def _set(self, transform: Any, authority: str, static: bool) -> bool:
        try:
            child = _strip_slash(str(transform.child_frame_id))
            parent = _strip_slash(str(transform.header.frame_id))
            stamp_ns = self.dialect.to_nsec(transform.header.stamp, "set_transform(): header.stamp")
            pose = _pose_of(transform.transform)
        except AttributeError:
            raise TypeError(
                "set_transform() takes a geometry_msgs/TransformStamped (header.frame_id, "
                f"child_frame_id, transform.translation, transform.rotation), got {transform!r}"
            ) from None
        problem = None
        (x, y, z), (qx, qy, qz, qw) = pose
        if child == parent:
            problem = (
                f'TF_SELF_TRANSFORM: Ignoring transform from authority "{authority}" with '
                f'frame_id and child_frame_id  "{child}" because they are the same'
            )
        elif not child:
            problem = (
                f'TF_NO_CHILD_FRAME_ID: Ignoring transform from authority "{authority}" '
                "because child_frame_id not set "
            )
        elif not parent:
            problem = (
                f'TF_NO_FRAME_ID: Ignoring transform with child_frame_id "{child}"  from '
                f'authority "{authority}" because frame_id not set'
            )
        elif any(math.isnan(value) for value in (x, y, z, qx, qy, qz, qw)):
            problem = (
                f'TF_NAN_INPUT: Ignoring transform for child_frame_id "{child}" from '
                f'authority "{authority}" because of a nan value in the transform '
                f"({x:f} {y:f} {z:f}) ({qx:f} {qy:f} {qz:f} {qw:f})"
            )
        elif abs(qx * qx + qy * qy + qz * qz + qw * qw - 1.0) >= (
            QUATERNION_NORMALIZATION_TOLERANCE
        ):
            problem = (
                f'TF_DENORMALIZED_QUATERNION: Ignoring transform for child_frame_id "{child}" '
                f'from authority "{authority}" because of an invalid quaternion in the '
                f"transform ({qx:f} {qy:f} {qz:f} {qw:f})"
            )
        if problem is not None:
            self.log("ERROR", problem)
            return False
        self._frames.setdefault(child, None)
        self._frames.setdefault(parent, None)
        cache = self._caches.get(child)
        if cache is None:
            cache = StaticCache() if static else TimeCache(self._cache_ns)
            self._caches[child] = cache
        refused = cache.insert(Stored(stamp_ns, parent, pose))
        if refused is not None:
            # tf2 logs every refusal; once per frame and reason keeps a 30 Hz loop readable.
            if (child, refused[:16]) not in self._reported:
                self._reported.add((child, refused[:16]))
                self.log(
                    "WARN",
                    f"{refused} for frame {child} (parent {parent}) at time "
                    f"{stamp_ns / NS_PER_S:f} according to authority {authority}",
                )
            return False
        self._authority[child] = authority
        return True

    def clear(self) -> None:
        """Forget every non-static transform (the frames stay known)."""
        for cache in self._caches.values():
            cache.clear()

    # ------------------------------------------------------------------ frame names
    def _known_frames_sentence(self) -> str:
        if not self._frames:
            return (
                " No transforms have arrived yet: a TransformListener needs a moment to fill "
                "its buffer, so pass a timeout (e.g. "
                f"{self.dialect.timeout_example}) or wait with can_transform(..., timeout)."
            )
        return " Known frames: " + ", ".join(sorted(self._frames)) + "."

    def _validate(self, what: str, frame_id: str) -> str:
        if not isinstance(frame_id, str):
            raise InvalidArgumentException(
                f"Invalid argument passed to {what} in tf2: a frame id is a string such as "
                f"'base_link', got {frame_id!r}"
            )
        if not frame_id:
            raise InvalidArgumentException(
                f"Invalid argument passed to {what} in tf2 frame_ids cannot be empty"
            )
        if frame_id.startswith("/"):
            raise InvalidArgumentException(
                f'Invalid argument "{frame_id}" passed to {what} in tf2 frame_ids cannot start '
                f"with a '/' like: '{frame_id}' (use '{frame_id.lstrip('/')}')"
            )
        if frame_id not in self._frames:
            raise LookupException(
                f'"{frame_id}" passed to {what} does not exist. '
                + self._known_frames_sentence().lstrip()
            )
        return frame_id

    def _frame_problem(self, what: str, frame_id: Any) -> bool:
        """tf2's warnFrameId: log and report a frame id that is empty or starts with '/'."""
        if isinstance(frame_id, str) and frame_id and not frame_id.startswith("/"):
            return False
        if isinstance(frame_id, str) and frame_id:
            self.log(
                "WARN",
                f'Invalid argument "{frame_id}" passed to {what} in tf2 frame_ids cannot start '
                "with a '/' like: ",
            )
        else:
            self.log("WARN", f"Invalid argument passed to {what} in tf2 frame_ids cannot be empty")
        return True

    # ------------------------------------------------------------------ the walk
    def _loop_error(self) -> tuple[int, str]:
        return _LOOKUP, (
            "The tf tree is invalid because it contains a loop.\n"
            + self.all_frames_as_string()
            + "\n"
        )

    def _latest_common_time(self, target: str, source: str) -> tuple[int, int, str]:
        """(code, time [ns], error): the newest time every link between the frames knows."""
        if source == target:
            cache = self._caches.get(source)
            return _OK, cache.latest()[0] if cache else 0, ""
        source_chain: list[tuple[int, str]] = []  # (newest stamp, parent) from source upwards
        common = math.inf
        frame = source
        for _ in range(MAX_GRAPH_DEPTH + 1):
            cache = self._caches.get(frame)
            stamp, parent = cache.latest() if cache else (0, None)
            if parent is None:
                break
            if stamp:
                common = min(common, stamp)
            source_chain.append((stamp, parent))
            frame = parent
            if frame == target:
                return _OK, 0 if common == math.inf else int(common), ""
        else:
            code, error = self._loop_error()
            return code, 0, error
        common = math.inf
        meeting = None
        source_parents = [parent for _, parent in source_chain]
        frame = target
        for _ in range(MAX_GRAPH_DEPTH + 1):
            cache = self._caches.get(frame)
            stamp, parent = cache.latest() if cache else (0, None)
            if parent is None:
                break
            if stamp:
                common = min(common, stamp)
            if parent in source_parents:
                meeting = parent
                break
            frame = parent
            if frame == source:
                return _OK, 0 if common == math.inf else int(common), ""
        else:
            code, error = self._loop_error()
            return code, 0, error
        if meeting is None:
            return _CONNECTIVITY, 0, self._connectivity_error(target, source)
        for stamp, parent in source_chain:
            if stamp:
                common = min(common, stamp)
            if parent == meeting:
                break
        return _OK, 0 if common == math.inf else int(common), ""

    @staticmethod
    def _connectivity_error(target: str, source: str) -> str:
        return (
            f"Could not find a connection between '{target}' and '{source}' because they are "
            "not part of the same tree.Tf has two or more unconnected trees."
        )

    def _walk(self, target: str, source: str, time_ns: int) -> tuple[int, str, _math.Pose, int]:
        """(code, error, pose of source in target, time used [ns])."""
        if source == target:
            return _OK, "", _math.IDENTITY, time_ns
        if time_ns == 0:
            code, time_ns, error = self._latest_common_time(target, source)
            if code != _OK:
                return code, error, _math.IDENTITY, 0
        source_to_top = _math.IDENTITY
        frame = top = source
        extrapolation_error, maybe_extrapolation = "", False
        for _ in range(MAX_GRAPH_DEPTH + 1):
            cache = self._caches.get(frame)
            if cache is None:  # the root of the tree has no cache
                top = frame
                break
            stored, error = cache.get(time_ns)
            if stored is None:  # there may still be a way round through the target's side
                top, extrapolation_error, maybe_extrapolation = frame, error, True
                break
            if frame == target:  # the target is an ancestor of the source
                return _OK, "", source_to_top, time_ns
            source_to_top = _math.compose(stored.pose, source_to_top)
            top, frame = frame, stored.parent
        else:
            code, error = self._loop_error()
            return code, error, _math.IDENTITY, 0
        target_to_top = _math.IDENTITY
        frame = target
        for _ in range(MAX_GRAPH_DEPTH + 1):
            if frame == top:
                break
            cache = self._caches.get(frame)
            if cache is None:
                break
            stored, error = cache.get(time_ns)
            if stored is None:
                return _EXTRAPOLATION, self._between(error, source, target), _math.IDENTITY, 0
            if frame == source:  # the source is an ancestor of the target
                return _OK, "", _math.invert(target_to_top), time_ns
            target_to_top = _math.compose(stored.pose, target_to_top)
            frame = stored.parent
        else:
            code, error = self._loop_error()
            return code, error, _math.IDENTITY, 0
        if frame != top:
            if maybe_extrapolation:
                error = self._between(extrapolation_error, source, target)
                return _EXTRAPOLATION, error, _math.IDENTITY, 0
            return _CONNECTIVITY, self._connectivity_error(target, source), _math.IDENTITY, 0
        return _OK, "", _math.compose(_math.invert(target_to_top), source_to_top), time_ns

    def _between(self, error: str, source: str, target: str) -> str:
        if not error:  # tf2 says nothing here; the frame's history was cleared
            error = "No transform is stored at that time (the buffer was cleared)"
        return f"{error}, when looking up transform from frame [{source}] to frame [{target}]"

    # ------------------------------------------------------------------ lookups
    def _message(self, target: str, source: str, pose: _math.Pose, time_ns: int) -> Any:
        result = get_message_class(self.dialect.transform_type)()
        result.header.stamp = self.dialect.stamp(time_ns)
        result.header.frame_id = target
        result.child_frame_id = source
        (result.transform.translation.x, result.transform.translation.y,
         result.transform.translation.z) = pose[0]  # fmt: skip
        rotation = result.transform.rotation
        rotation.x, rotation.y, rotation.z, rotation.w = pose[1]
        return result

    def lookup_transform_core(self, target_frame: str, source_frame: str, time: Any) -> Any:
        """The pose of `source_frame` in `target_frame` at `time` (Time(0): the latest) as a
        geometry_msgs/TransformStamped (header.frame_id = target, child_frame_id = source)."""
        time_ns = self.dialect.to_nsec(time, "lookup_transform()")
        if target_frame == source_frame:
            if time_ns == 0:
                cache = self._caches.get(target_frame)
                time_ns = cache.latest()[0] if cache else 0
            return self._message(target_frame, source_frame, _math.IDENTITY, time_ns)
        target = self._validate("lookupTransform argument target_frame", target_frame)
        source = self._validate("lookupTransform argument source_frame", source_frame)
        code, error, pose, used_ns = self._walk(target, source, time_ns)
        if code != _OK:
            raise _RAISE[code](error)
        return self._message(target, source, pose, used_ns)

    def lookup_transform_full_core(
        self,
        target_frame: str,
        target_time: Any,
        source_frame: str,
        source_time: Any,
        fixed_frame: str,
    ) -> Any:
        """Source at `source_time` into target at `target_time`, through `fixed_frame`, the
        frame taken to stay still between the two times."""
        for what, frame in (
            ("target_frame", target_frame),
            ("source_frame", source_frame),
            ("fixed_frame", fixed_frame),
        ):
            self._validate(f"lookupTransform argument {what}", frame)
        to_fixed = self.lookup_transform_core(fixed_frame, source_frame, source_time)
        to_target = self.lookup_transform_core(target_frame, fixed_frame, target_time)
        pose = _math.compose(_pose_of(to_target.transform), _pose_of(to_fixed.transform))
        stamp_ns = self.dialect.to_nsec(to_target.header.stamp, "stamp")
        return self._message(target_frame, source_frame, pose, stamp_ns)

    def can_transform_core(self, target_frame: str, source_frame: str, time: Any) -> tuple:
        """(possible, why not) for lookup_transform_core with these arguments."""
        time_ns = self.dialect.to_nsec(time, "can_transform()")
        if target_frame == source_frame:
            return True, ""
        if self._frame_problem("canTransform argument target_frame", target_frame):
            return False, ""
        if self._frame_problem("canTransform argument source_frame", source_frame):
            return False, ""
        missing = [
            f"canTransform: {role} {frame} does not exist."
            for role, frame in (("target_frame", target_frame), ("source_frame", source_frame))
            if frame not in self._frames
        ]
        if missing:
            return False, " ".join(missing)
        code, error, _, _ = self._walk(target_frame, source_frame, time_ns)
        return code == _OK, error

    def can_transform_full_core(
        self,
        target_frame: str,
        target_time: Any,
        source_frame: str,
        source_time: Any,
        fixed_frame: str,
    ) -> tuple:
        """(possible, why not) for lookup_transform_full_core with these arguments."""
        for role, frame in (
            ("target_frame", target_frame),
            ("source_frame", source_frame),
            ("fixed_frame", fixed_frame),
        ):
            if self._frame_problem(f"canTransform argument {role}", frame):
                return False, ""
        ok, error = self.can_transform_core(fixed_frame, source_frame, source_time)
        if not ok:
            return False, error
        return self.can_transform_core(target_frame, fixed_frame, target_time)

    def get_latest_common_time(self, target_frame: str, source_frame: str) -> Any:
        """The newest time at which a lookup between the two frames needs no extrapolation."""
        target = self._validate("get_latest_common_time", target_frame)
        source = self._validate("get_latest_common_time", source_frame)
        code, time_ns, error = self._latest_common_time(target, source)
        if code != _OK:
            raise TransformException(error)
        return self.dialect.time(time_ns)

    # ------------------------------------------------------------------ introspection
    def _parent_now(self, frame: str) -> str | None:
        cache = self._caches[frame]
        stored, _ = cache.get(0)
        return None if stored is None else stored.parent

    def all_frames_as_string(self) -> str:
        """One line per frame with a transform: "Frame odom exists with parent map."."""
        return "".join(
            f"Frame {frame} exists with parent {self._parent_now(frame) or _NO_PARENT}.\n"
            for frame in self._caches
        )

    def all_frames_as_yaml(self, current_time: float = 0.0) -> str:
        """The frame tree in tf2's YAML form (parent, broadcaster, rate, most_recent_transform,
        oldest_transform, buffer_length per child frame)."""
        if not self._frames:
            return "{}"
        lines = []
        for frame in self._caches:
            parent = self._parent_now(frame)
            if parent is None:
                continue
            count, oldest_ns, newest_ns = self._caches[frame].span()
            newest, oldest = newest_ns / NS_PER_S, oldest_ns / NS_PER_S
            rate = count / max(newest - oldest, 0.0001)
            lines += [
                f"{frame}: ",
                f"  parent: '{parent}'",
                f"  broadcaster: '{self._authority.get(frame, 'no recorded authority')}'",
                f"  rate: {rate:.3f}",
                f"  most_recent_transform: {newest:.3f}",
                f"  oldest_transform: {oldest:.3f}",
            ]
            if current_time > 0:
                lines.append(f"  transform_delay: {current_time - newest:.3f}")
            lines.append(f"  buffer_length: {newest - oldest:.3f}")
        return "".join(line + "\n" for line in lines)

    def _frameExists(self, frame_id: str) -> bool:
        return frame_id in self._frames

    def _getFrameStrings(self) -> list[str]:
        return list(self._frames)

    @property
    def cache_time(self) -> Any:
        return self.dialect.duration(self._cache_ns)
