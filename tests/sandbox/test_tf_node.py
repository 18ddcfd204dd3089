"""A real node in the node host that listens to the run's "tf" topic through tf2_ros and tf,
looks the robot up and publishes its yaw; and one that broadcasts its own frame."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from scipy.spatial.transform import Rotation

from sandbox.msgs import Time
from sandbox.msgs.geometry_msgs import TransformStamped
from sandbox.msgs.std_msgs import Float64
from sandbox.msgs.tf2_msgs import TFMessage
from sandbox.protocol import Envelope, Outcome, RobotTopic
from tests.sandbox.conftest import CROWBOT_TOPICS, crowbot_info
from tests.sandbox.test_host_harness import Parent, envelope

TF_TOPICS = [*CROWBOT_TOPICS, RobotTopic("tf", "tf2_msgs/TFMessage", "publish", 30.0)]
TURN_RATE = 0.5  # [rad/s] of the simulated robot
TF_PERIOD_S = 1 / 30  # [s] between the run's tf messages


def robot_tf(t: float) -> TFMessage:
    """map -> base_link of a robot turning on the spot at TURN_RATE, stamped t."""
    message = TransformStamped()
    message.header.frame_id, message.child_frame_id = "map", "base_link"
    message.header.stamp = Time.from_sec(t)
    message.transform.translation.x = 1.0
    r = message.transform.rotation
    r.x, r.y, r.z, r.w = Rotation.from_euler("z", TURN_RATE * t).as_quat()
    return TFMessage(transforms=[message])


def run_with_tf(code: str, workdir: Path) -> tuple[list[tuple[float, float]], object]:
    """Run `code`, delivering the run's tf at 30 Hz; (wake time, published yaw) pairs."""
    parent = Parent(code, workdir, info=crowbot_info("student", robot_topics=TF_TOPICS))
    frame = parent.next()
    now, next_tick, yaws = 0.0, 0, []
    for _ in range(2000):
        if not hasattr(frame, "wake_at_s"):
            break
        for published in frame.published:
            if published.topic == "yaw":
                yaws.append((now, Float64.deserialize(published.data).data))
        target = frame.wake_at_s if frame.wake_at_s is not None else now + 0.05
        deliveries: list[Envelope] = []
        # Every tf message the run has published up to the wake time, stamped when it was sent.
        while next_tick * TF_PERIOD_S <= target + 1e-9:
            deliveries.append(envelope("tf", robot_tf(next_tick * TF_PERIOD_S)))
            next_tick += 1
        now = target
        frame = parent.wake(now, deliveries)
    for published in frame.published:
        if published.topic == "yaw":
            yaws.append((now, Float64.deserialize(published.data).data))
    return yaws, frame


def assert_yaw_of_the_latest_tf(yaws: list[tuple[float, float]]) -> None:
    """Each yaw is the robot's at the newest tf stamp delivered by the wake it was sent at."""
    for wake_s, yaw in yaws:
        latest_stamp = math.floor(wake_s / TF_PERIOD_S + 1e-9) * TF_PERIOD_S
        assert math.cos(yaw - TURN_RATE * latest_stamp) > math.cos(1e-6), (wake_s, yaw)


def test_a_tf2_ros_listener_looks_up_the_robots_yaw(tmp_path: Path) -> None:
    yaws, exited = run_with_tf(
        """
        import rospy, tf2_ros
        from std_msgs.msg import Float64
        from tf.transformations import euler_from_quaternion
        rospy.init_node("yaw_reader")
        buffer = tf2_ros.Buffer()
        listener = tf2_ros.TransformListener(buffer)
        pub = rospy.Publisher("yaw", Float64, queue_size=10)
        rate = rospy.Rate(10)
        for _ in range(10):
            t = buffer.lookup_transform("map", "base_link", rospy.Time(0), rospy.Duration(1.0))
            q = t.transform.rotation
            yaw = euler_from_quaternion([q.x, q.y, q.z, q.w])[2]
            pub.publish(Float64(yaw))
            print("stamp %.4f yaw %.4f" % (t.header.stamp.to_sec(), yaw))
            rate.sleep()
        """,
        tmp_path,
    )
    assert exited.outcome is Outcome.FINISHED, exited
    assert len(yaws) == 10
    assert_yaw_of_the_latest_tf(yaws)
    seen = [yaw for _, yaw in yaws]
    assert seen == sorted(seen) and seen[-1] > seen[0]  # the robot turned; the node saw it turn


def test_a_classic_tf_listener_waits_then_looks_up(tmp_path: Path) -> None:
    yaws, exited = run_with_tf(
        """
        import rospy, tf
        from std_msgs.msg import Float64
        rospy.init_node("tf_classic")
        listener = tf.TransformListener()
        pub = rospy.Publisher("yaw", Float64, queue_size=10)
        listener.waitForTransform("/map", "/base_link", rospy.Time(0), rospy.Duration(2.0))
        try:
            listener.lookupTransform("map", "base_lnk", rospy.Time(0))
        except tf.LookupException as error:
            print("lookup refused:", error)
        rate = rospy.Rate(5)
        for _ in range(3):
            trans, rot = listener.lookupTransform("/map", "/base_link", rospy.Time(0))
            pub.publish(Float64(tf.transformations.euler_from_quaternion(rot)[2]))
            rate.sleep()
        """,
        tmp_path,
    )
    assert exited.outcome is Outcome.FINISHED, exited
    assert len(yaws) == 3
    assert_yaw_of_the_latest_tf(yaws)


def test_waiting_for_a_frame_nobody_publishes_times_out_in_node_time(tmp_path: Path) -> None:
    yaws, exited = run_with_tf(
        """
        import rospy, tf2_ros
        from std_msgs.msg import Float64
        rospy.init_node("patient")
        buffer = tf2_ros.Buffer()
        listener = tf2_ros.TransformListener(buffer)
        start = rospy.get_time()
        try:
            buffer.lookup_transform("map", "camera", rospy.Time(0), rospy.Duration(0.5))
        except tf2_ros.LookupException as error:
            rospy.Publisher("yaw", Float64, queue_size=1).publish(rospy.get_time() - start)
            raise
        """,
        tmp_path,
    )
    assert exited.outcome is Outcome.ERROR
    assert "LookupException" in exited.reason and "Known frames: base_link, map" in exited.reason
    assert [waited for _, waited in yaws] == [pytest.approx(0.5, abs=0.011)]


def test_broadcasters_publish_tf_and_latched_tf_static(tmp_path: Path) -> None:
    parent = Parent(
        """
        import rospy, tf, tf2_ros
        from geometry_msgs.msg import TransformStamped
        rospy.init_node("broadcaster")
        classic = tf.TransformBroadcaster()
        static = tf2_ros.StaticTransformBroadcaster()
        mount = TransformStamped()
        mount.header.stamp = rospy.Time.now()
        mount.header.frame_id, mount.child_frame_id = "base_link", "camera"
        mount.transform.rotation.w = 1.0
        static.sendTransform(mount)
        rospy.sleep(0.1)
        classic.sendTransform((0.5, 0, 0), tf.transformations.quaternion_from_euler(0, 0, 1.0),
                              rospy.Time.now(), "gripper", "base_link")
        """,
        tmp_path,
    )
    yields, exited = parent.run_lockstep()
    assert exited.outcome is Outcome.FINISHED, exited
    published = [e for frame in yields for e in frame.published]
    published += parent.last_published(exited)  # sent as the script ended
    assert [(e.topic, e.type) for e in published] == [
        ("tf_static", "tf2_msgs/TFMessage"),
        ("tf", "tf2_msgs/TFMessage"),
    ]
    (mount,) = TFMessage.deserialize(published[0].data).transforms
    assert (mount.header.frame_id, mount.child_frame_id) == ("base_link", "camera")
    (gripper,) = TFMessage.deserialize(published[1].data).transforms
    assert (gripper.header.frame_id, gripper.child_frame_id) == ("base_link", "gripper")
    assert gripper.header.stamp == Time.from_sec(0.1)
    r = gripper.transform.rotation
    assert Rotation.from_quat([r.x, r.y, r.z, r.w]).as_euler("zyx")[0] == pytest.approx(1.0)
    assert gripper.transform.translation.x == 0.5
