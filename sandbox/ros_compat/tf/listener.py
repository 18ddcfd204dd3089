"""tf.Transformer, tf.TransformerROS and tf.TransformListener: the classic tf API over a
tf2_ros.Buffer, with the behaviour of ROS 1 noetic (ros/geometry, tf/src/tf/listener.py):
frame ids may start with '/', which tf strips; lookupTransform returns ([x, y, z],
[x, y, z, w]); waitForTransform raises tf.Exception when the transform does not come in time;
transformPoint / transformPose / transformVector3 / transformQuaternion take stamped
geometry_msgs and return them in the target frame, stamped as the input.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import tf2_ros

from sandbox.msgs import Duration, Time

from . import transformations


def strip_leading_slash(frame_id: str) -> str:
    return frame_id[1:] if isinstance(frame_id, str) and frame_id.startswith("/") else frame_id


class Transformer:
    """A transform buffer without a subscription: fill it with setTransform()."""

    def __init__(self, interpolate: bool = True, cache_time: Any = None) -> None:
        self._buffer = tf2_ros.Buffer(cache_time, debug=False)
        self._using_dedicated_thread = False

    def allFramesAsString(self) -> str:
        return self._buffer.all_frames_as_string()

    def allFramesAsYAML(self) -> str:
        return self._buffer.all_frames_as_yaml()

    def setTransform(self, transform: Any, authority: str = "default_authority") -> None:
        self._buffer.set_transform(transform, authority)

    def canTransform(self, target_frame: str, source_frame: str, time: Any) -> bool:
        return self._buffer.can_transform(
            strip_leading_slash(target_frame), strip_leading_slash(source_frame), time
        )

    def canTransformFull(
        self,
        target_frame: str,
        target_time: Any,
        source_frame: str,
        source_time: Any,
        fixed_frame: str,
    ) -> bool:
        return self._buffer.can_transform_full(
            strip_leading_slash(target_frame),
            target_time,
            strip_leading_slash(source_frame),
            source_time,
            strip_leading_slash(fixed_frame),
        )

    def _require_listener(self) -> None:
        if not self._using_dedicated_thread:
            raise tf2_ros.TransformException(
                "cannot wait for transform without a dedicated thread that listens to incoming "
                "TF messages (use a tf.TransformListener, not a plain tf.Transformer)"
            )

    def waitForTransform(
        self,
        target_frame: str,
        source_frame: str,
        time: Any,
        timeout: Any,
        polling_sleep_duration: Any = None,
    ) -> None:
        """Return once target <- source at `time` can be looked up; raise tf.Exception with the
        reason if it cannot within `timeout` (a rospy.Duration)."""
        self._require_listener()
        source, target = strip_leading_slash(source_frame), strip_leading_slash(target_frame)
        possible, error = self._buffer.can_transform(
            target, source, time, timeout, return_debug_tuple=True
        )
        if not possible:
            raise tf2_ros.TransformException(
                error or f'no such transformation: "{source_frame}" -> "{target_frame}"'
            )

    def waitForTransformFull(
        self,
        target_frame: str,
        target_time: Any,
        source_frame: str,
        source_time: Any,
        fixed_frame: str,
        timeout: Any,
        polling_sleep_duration: Any = None,
    ) -> None:
        self._require_listener()
        possible, error = self._buffer.can_transform_full(
            strip_leading_slash(target_frame),
            target_time,
            strip_leading_slash(source_frame),
            source_time,
            strip_leading_slash(fixed_frame),
            timeout,
            return_debug_tuple=True,
        )
        if not possible:
            raise tf2_ros.TransformException(
                error or f'no such transformation: "{source_frame}" -> "{target_frame}"'
            )

    def clear(self) -> None:
        self._buffer.clear()

    def frameExists(self, frame_id: str) -> bool:
        """Whether `frame_id` is the child of a stored transform (as in noetic, the root frame
        of the tree, e.g. 'map', is not counted)."""
        return frame_id in self.getFrameStrings()

    def getFrameStrings(self) -> list[str]:
        """The frames that have a parent (noetic lists the child frames of its YAML dump)."""
        return [
            line[:-2]
            for line in self._buffer.all_frames_as_yaml().splitlines()
            if line.endswith(": ") and not line.startswith(" ")
        ]

    def getLatestCommonTime(self, source_frame: str, dest_frame: str) -> Time:
        return self._buffer.get_latest_common_time(
            strip_leading_slash(source_frame), strip_leading_slash(dest_frame)
        )

    def lookupTransform(
        self, target_frame: str, source_frame: str, time: Any
    ) -> tuple[list[float], list[float]]:
        """([x, y, z], [x, y, z, w]): the pose of `source_frame` in `target_frame` at `time`
        (rospy.Time(0): the latest)."""
        message = self._buffer.lookup_transform(
            strip_leading_slash(target_frame), strip_leading_slash(source_frame), time
        )
        t, r = message.transform.translation, message.transform.rotation
        return [t.x, t.y, t.z], [r.x, r.y, r.z, r.w]

    def lookupTransformFull(
        self,
        target_frame: str,
        target_time: Any,
        source_frame: str,
        source_time: Any,
        fixed_frame: str,
    ) -> tuple[list[float], list[float]]:
        message = self._buffer.lookup_transform_full(
            strip_leading_slash(target_frame),
            target_time,
            strip_leading_slash(source_frame),
            source_time,
            strip_leading_slash(fixed_frame),
        )
        t, r = message.transform.translation, message.transform.rotation
        return [t.x, t.y, t.z], [r.x, r.y, r.z, r.w]

    def lookupTwist(
        self, tracking_frame: str, observation_frame: str, time: Any, averaging_interval: Any
    ) -> tuple[tuple[float, ...], tuple[float, ...]]:
        """(linear, angular) velocity of `tracking_frame` seen from `observation_frame`,
        averaged over `averaging_interval` (a rospy.Duration) around `time`."""
        return self.lookupTwistFull(
            tracking_frame,
            observation_frame,
            observation_frame,
            (0, 0, 0),
            tracking_frame,
            time,
            averaging_interval,
        )

    def lookupTwistFull(
        self,
        tracking_frame: str,
        observation_frame: str,
        reference_frame: str,
        ref_point: Any,
        reference_point_frame: str,
        time: Any,
        averaging_interval: Any,
    ) -> tuple[tuple[float, ...], tuple[float, ...]]:
        """The twist of `tracking_frame` relative to `observation_frame`, expressed in
        `reference_frame` at `ref_point` (given in `reference_point_frame`)."""
        latest = self.getLatestCommonTime(observation_frame, tracking_frame)
        target = time if time else latest
        interval_ns = averaging_interval.to_nsec()
        end = min(target + Duration.from_nsec(interval_ns // 2), latest)
        start = max(Time.from_nsec(100_000) + averaging_interval, end) - averaging_interval
        seconds = (end - start).to_sec()
        start_t, start_q = self.lookupTransform(observation_frame, tracking_frame, start)
        end_t, end_q = self.lookupTransform(observation_frame, tracking_frame, end)
        turn = transformations.quaternion_multiply(
            transformations.quaternion_inverse(start_q), end_q
        )
        angle = 2.0 * math.atan2(math.sqrt(float(turn[:3] @ turn[:3])), turn[3])
        axis = turn[:3] / max(math.sqrt(float(turn[:3] @ turn[:3])), 1e-300)
        # The turn is expressed in the start pose; tf expresses it in the observation frame.
        axis = transformations.quaternion_matrix(start_q)[:3, :3] @ axis
        linear = (np.asarray(end_t) - np.asarray(start_t)) / seconds
        angular = axis * angle / seconds
        # Into the reference frame, then moved to the reference point: v_P = v_O + w x (P - O).
        _, to_reference = self.lookupTransform(reference_frame, observation_frame, target)
        rotation = transformations.quaternion_matrix(to_reference)[:3, :3]
        linear, angular = rotation @ linear, rotation @ angular
        origin, _ = self.lookupTransform(reference_frame, tracking_frame, target)
        point_t, point_q = self.lookupTransform(reference_frame, reference_point_frame, target)
        point = transformations.quaternion_matrix(point_q)[:3, :3] @ as_point(ref_point)
        linear = linear + np.cross(angular, np.asarray(point_t) + point - np.asarray(origin))
        return tuple(float(v) for v in linear), tuple(float(v) for v in angular)

    def setUsingDedicatedThread(self, value: bool) -> None:
        self._using_dedicated_thread = bool(value)

    def getTFPrefix(self) -> str:
        return ""


def as_point(value: Any) -> list[float]:
    return [float(v) for v in value][:3]


class TransformerROS(Transformer):
    """Transformer plus transforms of stamped geometry_msgs."""

    def asMatrix(self, target_frame: str, hdr: Any) -> np.ndarray:
        """4x4 matrix taking coordinates in hdr.frame_id at hdr.stamp into `target_frame`."""
        translation, rotation = self.lookupTransform(target_frame, hdr.frame_id, hdr.stamp)
        return self.fromTranslationRotation(translation, rotation)

    def fromTranslationRotation(self, translation: Any, rotation: Any) -> np.ndarray:
        return transformations.translation_matrix(translation) @ (
            transformations.quaternion_matrix(rotation)
        )

    @staticmethod
    def _stamped_like(message: Any, target_frame: str) -> Any:
        result = type(message)()
        result.header.stamp = message.header.stamp
        result.header.frame_id = target_frame
        return result

    def transformPoint(self, target_frame: str, ps: Any) -> Any:
        """A geometry_msgs/PointStamped in `target_frame`."""
        matrix = self.asMatrix(target_frame, ps.header)
        x, y, z = (matrix @ [ps.point.x, ps.point.y, ps.point.z, 1.0])[:3]
        result = self._stamped_like(ps, target_frame)
        result.point.x, result.point.y, result.point.z = float(x), float(y), float(z)
        return result

    def transformVector3(self, target_frame: str, v3s: Any) -> Any:
        """A geometry_msgs/Vector3Stamped rotated into `target_frame` (no translation)."""
        matrix = self.asMatrix(target_frame, v3s.header)
        x, y, z = matrix[:3, :3] @ [v3s.vector.x, v3s.vector.y, v3s.vector.z]
        result = self._stamped_like(v3s, target_frame)
        result.vector.x, result.vector.y, result.vector.z = float(x), float(y), float(z)
        return result

    def transformQuaternion(self, target_frame: str, ps: Any) -> Any:
        """A geometry_msgs/QuaternionStamped turned into `target_frame`."""
        matrix = self.asMatrix(target_frame, ps.header)
        q = ps.quaternion
        turned = matrix @ transformations.quaternion_matrix([q.x, q.y, q.z, q.w])
        result = self._stamped_like(ps, target_frame)
        out = result.quaternion
        out.x, out.y, out.z, out.w = (
            float(v) for v in transformations.quaternion_from_matrix(turned)
        )
        return result

    def transformPose(self, target_frame: str, ps: Any) -> Any:
        """A geometry_msgs/PoseStamped in `target_frame`."""
        matrix = self.asMatrix(target_frame, ps.header)
        p, o = ps.pose.position, ps.pose.orientation
        pose = transformations.translation_matrix([p.x, p.y, p.z]) @ (
            transformations.quaternion_matrix([o.x, o.y, o.z, o.w])
        )
        moved = matrix @ pose
        result = self._stamped_like(ps, target_frame)
        position, orientation = result.pose.position, result.pose.orientation
        position.x, position.y, position.z = (float(v) for v in moved[:3, 3])
        orientation.x, orientation.y, orientation.z, orientation.w = (
            float(v) for v in transformations.quaternion_from_matrix(moved)
        )
        return result

    def transformPointCloud(self, target_frame: str, point_cloud: Any) -> Any:
        """A sensor_msgs/PointCloud with every point in `target_frame` (channels kept)."""
        matrix = self.asMatrix(target_frame, point_cloud.header)
        result = self._stamped_like(point_cloud, target_frame)
        result.channels = point_cloud.channels
        points = []
        for point in point_cloud.points:
            x, y, z = (matrix @ [point.x, point.y, point.z, 1.0])[:3]
            moved = type(point)()
            moved.x, moved.y, moved.z = float(x), float(y), float(z)
            points.append(moved)
        result.points = points
        return result


class TransformListener(TransformerROS):
    """A TransformerROS that subscribes to "tf" and "tf_static" (needs rospy.init_node first).

    listener = tf.TransformListener()
    listener.waitForTransform("map", "base_link", rospy.Time(0), rospy.Duration(2.0))
    (trans, rot) = listener.lookupTransform("map", "base_link", rospy.Time(0))
    """

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        TransformerROS.__init__(self, *args, **kwargs)
        self._listener = tf2_ros.TransformListener(self._buffer)
        self.setUsingDedicatedThread(True)
