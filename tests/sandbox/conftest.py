"""Shared fixtures for the sandbox tests: one real launcher (bubblewrap + seccomp) per module.

The sandbox is the thing under test, so these tests never fall back to running code unsandboxed:
without bubblewrap they fail and say how to install it (scripts/test installs it)."""

from __future__ import annotations

import dataclasses
import time

import pytest

from sandbox import bwrap
from sandbox.launcher import Launcher
from sandbox.limits import DEFAULT_LIMITS
from sandbox.protocol import Api, Clock, Exited, Finishing, NodeInfo, RobotTopic, Yield

# Short budgets so the attack tests that must be killed do not take long.
TEST_LIMITS = dataclasses.replace(
    DEFAULT_LIMITS, step_budget_s=1.0, first_step_budget_s=4.0, shutdown_budget_s=3.0
)

CROWBOT_TOPICS = [
    RobotTopic("Distance", "std_msgs/Int32", "publish", 20.0),
    RobotTopic("Button", "std_msgs/Bool", "publish", 20.0),
    RobotTopic("Light", "std_msgs/Int32MultiArray", "publish", 20.0),
    RobotTopic("Line", "std_msgs/Int32MultiArray", "publish", 20.0),
    RobotTopic("Control", "geometry_msgs/Twist", "subscribe"),
    RobotTopic("Leds", "std_msgs/Int32MultiArray", "subscribe"),
    RobotTopic("Buzzer", "std_msgs/Bool", "subscribe"),
]


def crowbot_info(name: str = "node", **overrides: object) -> NodeInfo:
    """What a CrowBot node called `name` is told about its run; `overrides` replace any other
    field (clock, params, allow_new_topics, ...)."""
    fields: dict[str, object] = {
        "node_name": name,
        "robot": "crowbot",
        "robot_topics": CROWBOT_TOPICS,
        "velocity_topic": "Control",
        "clock": Clock.LOCKSTEP,
    }
    fields.update(overrides)
    return NodeInfo(**fields)  # type: ignore[arg-type]


@pytest.fixture(scope="module")
def launcher():
    problem = bwrap.probe()
    if problem:
        pytest.fail(f"the sandbox tests need bubblewrap: {problem} (./scripts/test installs it)")
    launcher = Launcher(limits=TEST_LIMITS, pool_size=2)
    yield launcher
    launcher.close()


class WarmOnlyLauncher(Launcher):
    """Hands out warm nodes only (their heavy libraries imported before the seal), waiting for
    the pool to refill: the walls must hold for those as for nodes started cold."""

    def start(self, name: str):
        deadline = time.monotonic() + 60.0
        while self.warm_count < 1:
            assert time.monotonic() < deadline, "the warm pool did not refill within 60 s"
            time.sleep(0.02)
        return super().start(name)


# The warm half waits for the pool to refill before every node (seconds per test): the fast
# set (-m "not slow") runs every attack on cold nodes only; the full suite runs both.
@pytest.fixture(scope="module", params=[pytest.param("warm", marks=pytest.mark.slow), "cold"])
def warm_and_cold_launcher(request):
    """A launcher whose nodes all come from the warm pool, then one whose nodes all start cold
    (importing numpy and the rest only when the student's code does)."""
    problem = bwrap.probe()
    if problem:
        pytest.fail(f"the sandbox tests need bubblewrap: {problem} (./scripts/test installs it)")
    if request.param == "warm":
        launcher = WarmOnlyLauncher(limits=TEST_LIMITS, pool_size=2)
    else:
        launcher = Launcher(limits=TEST_LIMITS, pool_size=0)
    yield launcher
    launcher.close()


def run_script(launcher: Launcher, code: str, name: str = "attack", api: Api = Api.AUTO):
    """Load `code` as a node and return (first reply, node). The caller closes the node."""
    node = launcher.start(name)
    reply = node.load(code, f"{name}.py", api, crowbot_info(name))
    if isinstance(reply, Finishing):  # the script ended: wait for its Exited (end budget)
        reply = node.shutdown("script ended")
    assert isinstance(reply, (Yield, Exited))
    return reply, node
