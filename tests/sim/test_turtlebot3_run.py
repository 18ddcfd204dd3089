"""The TurtleBot3 in a real lockstep run (sandboxed node, run engine, recording): a rospy node that
drives forward on cmd_vel moves the robot, and its scan and odometry reach the node."""

from __future__ import annotations

import dataclasses
import json

import pytest

from sandbox import bwrap
from sandbox.launcher import Launcher
from sandbox.limits import DEFAULT_LIMITS
from server.runs.run import Run
from server.runs.spec import NodeSpec, RunSpec
from server.runs.state import RunState

# Drives ahead until the scan sees the board within 0.4 m, and logs what it saw (as JSON on one
# line) when it stops, so the test can check the scan and the odometry arrived as the real
# robot sends them.
FORWARD = """
import json
import rospy
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from sensor_msgs.msg import LaserScan

seen = {"scan": None, "odom_x": None}


def on_scan(scan):
    seen["scan"] = (len(scan.ranges), scan.header.frame_id, float(scan.ranges[0]))


def on_odom(odom):
    seen["odom_x"] = odom.pose.pose.position.x


rospy.init_node("forward")
rospy.Subscriber("scan", LaserScan, on_scan)
rospy.Subscriber("odom", Odometry, on_odom)
pub = rospy.Publisher("cmd_vel", Twist, queue_size=1)
rate = rospy.Rate(10)
while not rospy.is_shutdown():
    cmd = Twist()
    scan = seen["scan"]
    if scan is not None and 0.0 < scan[2] < 0.4:
        pub.publish(cmd)
        rospy.loginfo("stopped " + json.dumps(seen))
        rospy.signal_shutdown("at the board")
        break
    cmd.linear.x = 0.2
    pub.publish(cmd)
    rate.sleep()
"""


@pytest.fixture(scope="module")
def launcher():
    problem = bwrap.probe()
    if problem:
        pytest.fail(f"the run tests need bubblewrap: {problem} (./scripts/test installs it)")
    limits = dataclasses.replace(DEFAULT_LIMITS, step_budget_s=2.0, first_step_budget_s=8.0)
    launcher = Launcher(limits=limits, pool_size=1)
    yield launcher
    launcher.close()


def test_a_rospy_node_drives_the_burger_to_the_board(tmp_path, launcher) -> None:
    spec = RunSpec(
        robot="turtlebot3",
        world="wall_approach",
        spawn="far",  # base_link at x = 0.35 m, the board's face at x = 1.40 m
        nodes=(NodeSpec(name="forward", code=FORWARD, filename="forward.py"),),
        duration_s=6.0,
    )
    run = Run(spec, launcher, tmp_path / "run")
    result = run.execute()
    assert result.state is RunState.FINISHED, result.reason
    assert result.metrics["collisions"] == 0
    # It drove ~0.65 m: the scanner, 32 mm behind base_link, stopped under 0.4 m from the board.
    pose_x = run.sim.state.pose.x
    assert 1.40 - 0.4 - 0.032 - 0.06 < pose_x < 1.40 - 0.3
    logs = (tmp_path / "run" / "logs" / "forward.log").read_text()
    seen = json.loads(logs.split("stopped ", 1)[1].splitlines()[0])
    assert seen["scan"][:2] == [360, "base_scan"]
    assert seen["odom_x"] == pytest.approx(pose_x - 0.35, abs=0.05)
