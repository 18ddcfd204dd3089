"""tf2_ros.Buffer (and tf.Transformer over it) fed by set_transform: chains, inverses,
interpolation, time 0, extrapolation and lookup errors with tf2's sentences, static frames,
the cache window, and buffer.transform() of geometry_msgs."""

from __future__ import annotations

import math

import pytest
from scipy.spatial.transform import Rotation

from sandbox.host import install_ros_compat
from sandbox.msgs import Duration, Time, get_message_class
from sandbox.msgs.geometry_msgs import PoseStamped, TransformStamped

install_ros_compat()
import tf  # noqa: E402
import tf2_geometry_msgs  # noqa: E402, F401  (registers the geometry_msgs types)
import tf2_ros  # noqa: E402


def stamped(parent: str, child: str, t: float, x: float = 0.0, y: float = 0.0, yaw: float = 0.0):
    message = TransformStamped()
    message.header.frame_id, message.child_frame_id = parent, child
    message.header.stamp = Time.from_sec(t)
    message.transform.translation.x, message.transform.translation.y = x, y
    r = message.transform.rotation
    r.x, r.y, r.z, r.w = Rotation.from_euler("z", yaw).as_quat()
    return message


def yaw_of(message) -> float:
    r = message.transform.rotation
    return float(Rotation.from_quat([r.x, r.y, r.z, r.w]).as_euler("zyx")[0])


def xy(message) -> tuple[float, float]:
    return message.transform.translation.x, message.transform.translation.y


@pytest.fixture
def robot() -> tf2_ros.Buffer:
    """map -> odom (fixed), odom -> base_link moving 1 m/s along x and turning 0.1 rad/s,
    base_link -> laser (static, 0.2 m ahead, facing backwards), for t = 1..5 s."""
    buffer = tf2_ros.Buffer()
    for t in range(1, 6):
        assert buffer.set_transform(stamped("map", "odom", t, x=1.0, y=2.0, yaw=math.pi / 2), "a")
        assert buffer.set_transform(stamped("odom", "base_link", t, x=t, yaw=0.1 * t), "a")
    assert buffer.set_transform_static(stamped("base_link", "laser", 0, x=0.2, yaw=math.pi), "a")
    return buffer


def expected_laser_in_map(t: float) -> tuple[float, float, float]:
    base = (1.0 - 0.0, 2.0 + t)  # odom is turned 90 degrees: odom x is map y
    heading = math.pi / 2 + 0.1 * t
    laser = (base[0] + 0.2 * math.cos(heading), base[1] + 0.2 * math.sin(heading))
    yaw = (heading + math.pi + math.pi) % (2 * math.pi) - math.pi
    return laser[0], laser[1], yaw


def test_a_chain_of_four_frames_composes_and_time_zero_is_the_latest(robot) -> None:
    result = robot.lookup_transform("map", "laser", Time(0))
    x, y, yaw = expected_laser_in_map(5.0)
    assert xy(result) == pytest.approx((x, y)) and yaw_of(result) == pytest.approx(yaw)
    assert result.header.stamp == Time(5) and result.header.frame_id == "map"
    assert result.child_frame_id == "laser"


def test_the_inverse_lookup_is_the_inverse_transform(robot) -> None:
    there = robot.lookup_transform("map", "laser", Time(3))
    back = robot.lookup_transform("laser", "map", Time(3))
    yaw = yaw_of(there)
    x, y = xy(there)
    # back = -R^T t, -yaw
    assert xy(back) == pytest.approx(
        (-(math.cos(yaw) * x + math.sin(yaw) * y), -(-math.sin(yaw) * x + math.cos(yaw) * y))
    )
    assert yaw_of(back) == pytest.approx(-yaw)


def test_between_stamps_translation_is_linear_and_rotation_slerped(robot) -> None:
    result = robot.lookup_transform("odom", "base_link", Time.from_sec(2.25))
    assert xy(result) == pytest.approx((2.25, 0.0))
    assert yaw_of(result) == pytest.approx(0.225)
    x, y, yaw = expected_laser_in_map(3.5)
    through = robot.lookup_transform("map", "laser", Time.from_sec(3.5))
    assert xy(through) == pytest.approx((x, y)) and yaw_of(through) == pytest.approx(yaw)


def test_siblings_are_found_through_their_common_parent() -> None:
    buffer = tf2_ros.Buffer()
    buffer.set_transform(stamped("base_link", "left", 1.0, y=0.1), "a")
    buffer.set_transform(stamped("base_link", "right", 1.0, y=-0.1, yaw=math.pi), "a")
    result = buffer.lookup_transform("left", "right", Time(0))
    assert xy(result) == pytest.approx((0.0, -0.2))
    assert abs(yaw_of(result)) == pytest.approx(math.pi)


def test_time_zero_is_the_latest_common_time_of_the_chain() -> None:
    buffer = tf2_ros.Buffer()
    for t in (1.0, 2.0, 3.0):
        buffer.set_transform(stamped("map", "odom", t), "a")
    for t in (1.0, 2.0):  # the lower link lags behind
        buffer.set_transform(stamped("odom", "base_link", t, x=t), "a")
    assert buffer.get_latest_common_time("map", "base_link") == Time(2)
    assert buffer.lookup_transform("map", "base_link", Time(0)).header.stamp == Time(2)


def test_future_and_past_extrapolation_raise_with_tf2s_sentences(robot) -> None:
    with pytest.raises(tf2_ros.ExtrapolationException) as future:
        robot.lookup_transform("map", "laser", Time.from_sec(7.5))
    assert str(future.value) == (
        "Lookup would require extrapolation 2.500000000s into the future.  Requested time "
        "7.500000000 but the latest data is at time 5.000000000, when looking up transform "
        "from frame [laser] to frame [map]"
    )
    with pytest.raises(tf2_ros.ExtrapolationException, match=r"0\.500000000s into the past"):
        robot.lookup_transform("map", "laser", Time.from_sec(0.5))
    assert not robot.can_transform("map", "laser", Time.from_sec(7.5))
    possible, why = robot.can_transform("map", "laser", Time(9), return_debug_tuple=True)
    assert not possible and "into the future" in why


def test_unknown_frames_name_the_known_ones(robot) -> None:
    with pytest.raises(tf2_ros.LookupException) as error:
        robot.lookup_transform("map", "base_footprint", Time(0))
    assert str(error.value).startswith(
        '"base_footprint" passed to lookupTransform argument source_frame does not exist.'
    )
    assert "Known frames: base_link, laser, map, odom." in str(error.value)
    with pytest.raises(tf2_ros.LookupException, match="No transforms have arrived yet"):
        tf2_ros.Buffer().lookup_transform("map", "base_link", Time(0))
    assert isinstance(error.value, tf2_ros.TransformException)
    assert isinstance(error.value, tf.Exception)


def test_separate_trees_raise_connectivity(robot) -> None:
    robot.set_transform(stamped("world", "tree", 5.0), "a")
    with pytest.raises(tf2_ros.ConnectivityException, match="not part of the same tree"):
        robot.lookup_transform("map", "tree", Time(0))


def test_a_leading_slash_is_stripped_when_stored_and_refused_by_tf2_lookups(robot) -> None:
    robot.set_transform(stamped("/base_link", "/camera", 5.0, x=0.1), "a")
    assert xy(robot.lookup_transform("base_link", "camera", Time(0))) == pytest.approx((0.1, 0))
    with pytest.raises(tf2_ros.InvalidArgumentException, match="cannot start with a '/'"):
        robot.lookup_transform("/map", "camera", Time(0))
    assert not robot.can_transform("/map", "camera", Time(0))
    # The classic tf API strips the slash, as ROS's tf does.
    listener = tf.TransformerROS()
    listener._buffer = robot
    trans, rot = listener.lookupTransform("/base_link", "/camera", Time(0))
    assert trans == pytest.approx([0.1, 0.0, 0.0]) and rot == pytest.approx([0, 0, 0, 1])


def test_bad_transforms_are_ignored_with_tf2s_reasons() -> None:
    buffer = tf2_ros.BufferCore()
    assert not buffer.set_transform(stamped("a", "a", 1.0), "me")
    assert not buffer.set_transform(stamped("", "b", 1.0), "me")
    nan = stamped("a", "b", 1.0, x=float("nan"))
    assert not buffer.set_transform(nan, "me")
    bad = stamped("a", "b", 1.0)
    bad.transform.rotation.w = 0.0
    bad.transform.rotation.z = 0.0
    assert not buffer.set_transform(bad, "me")
    assert buffer.set_transform(stamped("a", "b", 1.0), "me")
    assert not buffer.set_transform(stamped("a", "b", 1.0), "me")
    reasons = " ".join(buffer.problems)
    for reason in ("TF_SELF_TRANSFORM", "TF_NO_FRAME_ID", "TF_NAN_INPUT",
                   "TF_DENORMALIZED_QUATERNION", "TF_REPEATED_DATA"):  # fmt: skip
        assert reason in reasons


def test_the_cache_keeps_only_cache_time_behind_the_newest() -> None:
    buffer = tf2_ros.Buffer(cache_time=Duration(2))
    for t in range(1, 8):
        buffer.set_transform(stamped("map", "base_link", t, x=t), "a")
    assert xy(buffer.lookup_transform("map", "base_link", Time(5)))[0] == pytest.approx(5.0)
    with pytest.raises(tf2_ros.ExtrapolationException, match="earliest data is at time 5"):
        buffer.lookup_transform("map", "base_link", Time(4))
    assert not buffer.set_transform(stamped("map", "base_link", 1.0), "a")  # TF_OLD_DATA
    buffer.clear()
    assert not buffer.can_transform("map", "base_link", Time(0))


def test_static_transforms_hold_at_every_time_and_survive_clear(robot) -> None:
    for t in (0.0, 1.0, 3.3, 1000.0):
        result = robot.lookup_transform("base_link", "laser", Time.from_sec(t))
        assert xy(result) == pytest.approx((0.2, 0.0))
    robot.clear()
    assert robot.can_transform("base_link", "laser", Time(0))
    assert not robot.can_transform("map", "laser", Time(0))


def test_the_same_frame_is_the_identity_even_when_unknown(robot) -> None:
    identity = robot.lookup_transform("nowhere", "nowhere", Time(3))
    assert xy(identity) == (0.0, 0.0) and identity.transform.rotation.w == 1.0


def test_full_lookup_goes_through_the_fixed_frame(robot) -> None:
    # Where the laser at t=2 is, seen from the base at t=4, with the map held still.
    result = robot.lookup_transform_full("base_link", Time(4), "laser", Time(2), "map")
    laser_then = robot.lookup_transform("map", "laser", Time(2))
    base_now = robot.lookup_transform("base_link", "map", Time(4))
    yaw_now = yaw_of(base_now)
    lx, ly = xy(laser_then)
    bx, by = xy(base_now)
    expected = (
        math.cos(yaw_now) * lx - math.sin(yaw_now) * ly + bx,
        math.sin(yaw_now) * lx + math.cos(yaw_now) * ly + by,
    )
    assert xy(result) == pytest.approx(expected)
    assert robot.can_transform_full("base_link", Time(4), "laser", Time(2), "map")


def test_frame_listings(robot) -> None:
    text = robot.all_frames_as_string()
    assert "Frame base_link exists with parent odom.\n" in text
    assert "Frame laser exists with parent base_link.\n" in text
    yaml_text = robot.all_frames_as_yaml()
    assert "odom: \n  parent: 'map'\n  broadcaster: 'a'\n" in yaml_text
    assert "  most_recent_transform: 5.000\n  oldest_transform: 1.000\n" in yaml_text
    transformer = tf.Transformer()
    transformer._buffer = robot
    assert transformer.frameExists("base_link") and not transformer.frameExists("nope")
    assert set(transformer.getFrameStrings()) == {"odom", "base_link", "laser"}


def test_buffer_transform_moves_a_pose_stamped_into_the_target_frame(robot) -> None:
    pose = PoseStamped()
    pose.header.frame_id, pose.header.stamp = "laser", Time(3)
    pose.pose.position.x = 1.0  # one metre in front of the laser, i.e. behind the robot
    pose.pose.orientation.w = 1.0
    moved = robot.transform(pose, "map")
    assert moved.header.frame_id == "map" and moved.header.stamp == Time(3)
    heading = math.pi / 2 + 0.3
    base = (1.0, 2.0 + 3.0)
    assert (moved.pose.position.x, moved.pose.position.y) == pytest.approx(
        (base[0] - 0.8 * math.cos(heading), base[1] - 0.8 * math.sin(heading))
    )
    q = moved.pose.orientation
    yaw = Rotation.from_quat([q.x, q.y, q.z, q.w]).as_euler("zyx")[0]
    assert math.cos(yaw - (heading + math.pi)) == pytest.approx(1.0)
    # The classic listener gives the same pose.
    listener = tf.TransformerROS()
    listener._buffer = robot
    same = listener.transformPose("map", pose)
    assert same.pose.position.x == pytest.approx(moved.pose.position.x)
    assert same.pose.position.y == pytest.approx(moved.pose.position.y)


def test_point_and_vector_transforms_when_their_types_exist(robot) -> None:
    try:
        point_class = get_message_class("geometry_msgs/PointStamped")
        vector_class = get_message_class("geometry_msgs/Vector3Stamped")
    except KeyError:
        pytest.skip("geometry_msgs/PointStamped is not defined yet (the msgs helper adds it)")
    point = point_class()
    point.header.frame_id, point.header.stamp = "base_link", Time(2)
    point.point.x = 1.0
    moved = robot.transform(point, "odom")
    assert (moved.point.x, moved.point.y) == pytest.approx((2.0 + math.cos(0.2), math.sin(0.2)))
    vector = vector_class()
    vector.header.frame_id, vector.header.stamp = "base_link", Time(2)
    vector.vector.x = 1.0
    turned = robot.transform(vector, "odom")
    assert (turned.vector.x, turned.vector.y) == pytest.approx((math.cos(0.2), math.sin(0.2)))


def test_unregistered_types_and_wrong_times_get_sentences(robot) -> None:
    with pytest.raises(tf2_ros.TypeException, match="is not loaded or supported"):
        robot.transform(TransformStamped(), "map")
    with pytest.raises(TypeError, match=r"rospy\.Time\(0\) for the latest"):
        robot.lookup_transform("map", "laser", 0)
    with pytest.raises(AttributeError, match="BufferClient is not available"):
        tf2_ros.BufferClient  # noqa: B018
    with pytest.raises(TypeError, match=r"tf\.TransformBroadcaster's"):
        tf2_ros.transform_broadcaster._as_list((0, 0, 0), ((0, 0, 0, 1), Time(0)), "x")


def test_a_transformer_without_a_listener_cannot_wait(robot) -> None:
    transformer = tf.Transformer(True, Duration(10))
    transformer.setTransform(stamped("map", "base_link", 1.0, x=2.0))
    assert transformer.lookupTransform("map", "base_link", Time(0))[0] == pytest.approx(
        [2.0, 0.0, 0.0]
    )
    with pytest.raises(tf.Exception, match="dedicated thread"):
        transformer.waitForTransform("map", "base_link", Time(0), Duration(1))
