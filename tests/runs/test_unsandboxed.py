"""The unsandboxed step-API runner (server/sim/unsandboxed.py) gives a controller what a lockstep
sandboxed run gives it: the same commands at the same times, the same pose trace, the same
refusals; and it says that it runs unsandboxed."""

from __future__ import annotations

import logging
import math

import numpy as np
import pytest
from mcap.reader import make_reader

from sandbox.msgs.geometry_msgs import Twist
from sandbox.msgs.tf2_msgs import TFMessage
from server.runs.run import Run
from server.runs.spec import NodeSpec, RunSpec
from server.runs.state import RunState
from server.sim.unsandboxed import run_step_controller

DURATION_S = 4.0  # [s]
SEED = 3
# Steers by the noisy ranger, so the trace depends on every reading; asks for a colour the robot
# refuses now and then (a 4-value Leds), which both runs must log the same way.
CONTROLLER = """
import math

RATE_HZ = 20
calls = 0

def step(obs):
    global calls
    calls += 1
    if obs.Distance is None:
        return None
    turn = 0.02 * (obs.Distance.data - 40) + 0.3 * math.sin(obs.time)
    command = {"Control": (0.1, turn)}
    if calls % 25 == 0:
        command["Leds"] = [255, 0, 0, 7]
    return command
"""


def _recorded(run_dir, topic: str) -> list[tuple[float, bytes]]:
    with open(run_dir / "recording.mcap", "rb") as f:
        return [
            (message.log_time / 1e9, message.data)
            for _, channel, message in make_reader(f).iter_messages()
            if channel.topic == "/" + topic
        ]


def _yaw(rotation) -> float:
    return 2.0 * math.atan2(rotation.z, rotation.w)


@pytest.fixture(scope="module")
def both(launcher, tmp_path_factory):
    out = tmp_path_factory.mktemp("lockstep") / "run"
    spec = RunSpec(
        "crowbot",
        "wall_approach",
        (NodeSpec("drive", CONTROLLER, "drive.py"),),
        duration_s=DURATION_S,
        seed=SEED,
    )
    run = Run(spec, launcher, out)
    result = run.execute()
    assert result.state is RunState.FINISHED, result.reason
    local = run_step_controller(CONTROLLER, "crowbot", "wall_approach", DURATION_S, SEED)
    return run, out, local


def test_the_commands_are_the_same_at_the_same_times(both) -> None:
    _, out, local = both
    sandboxed = [
        (t, Twist.deserialize(data).linear.x, Twist.deserialize(data).angular.z)
        for t, data in _recorded(out, "Control")
    ]
    ours = [(m.time_s, m.message.linear.x, m.message.angular.z) for m in local.topic("Control")]
    # The run records one more: the zero velocity every run ends with.
    assert sandboxed[-1][1:] == (0.0, 0.0)
    assert len(ours) > 50
    np.testing.assert_allclose(np.array(sandboxed[:-1]), np.array(ours), rtol=0, atol=1e-9)


def test_the_pose_trace_is_the_same(both) -> None:
    run, out, local = both
    by_time = {round(t, 9): (x, y, yaw) for t, x, y, yaw in local.poses}
    compared = 0
    for time_s, data in _recorded(out, "tf"):
        body = TFMessage.deserialize(data).transforms[0]
        assert (body.header.frame_id, body.child_frame_id) == ("map", "base_link")
        x, y, yaw = by_time[round(time_s, 9)]  # /tf is recorded at wake times and the end
        translation = body.transform.translation
        assert (translation.x, translation.y) == pytest.approx((x, y), abs=1e-9)
        assert math.remainder(_yaw(body.transform.rotation) - yaw, math.tau) == pytest.approx(
            0.0, abs=1e-9
        )
        compared += 1
    assert compared > 60
    end = run.sim.state.pose
    assert (end.x, end.y, end.yaw) == pytest.approx(tuple(local.poses[-1][1:]), abs=1e-9)
    assert local.poses[-1][0] == DURATION_S
    # It went somewhere: the comparison is not of two robots standing still.
    assert math.hypot(end.x - local.poses[0][1], end.y - local.poses[0][2]) > 0.2


def test_refused_commands_are_logged_the_same_way(both) -> None:
    _, out, local = both
    node_log = (out / "logs" / "drive.log").read_text()
    refusals = [line for line in node_log.splitlines() if "[robot] rejected Leds" in line]
    assert len(local.logs) == len(refusals) > 0
    for ours, theirs in zip(local.logs, refusals, strict=True):
        assert theirs.endswith(ours)


def test_it_says_it_runs_unsandboxed_and_takes_a_plain_function(caplog) -> None:
    seen = []

    def step(obs):
        seen.append((obs.time, obs.Distance))
        return 0.05, 0.0

    with caplog.at_level(logging.WARNING, logger="robodojo.sim.unsandboxed"):
        result = run_step_controller(step, "crowbot", "wall_approach", 1.0, rate_hz=10)
    assert any(r.message.startswith("UNSANDBOXED") for r in caplog.records)
    assert [round(t, 9) for t, _ in seen] == [round(0.1 * k, 9) for k in range(10)]
    assert seen[0][1] is None and seen[1][1] is not None  # nothing before it subscribed
    assert result.poses[-1][1] > result.poses[0][1]  # drove forward
    assert result.sim.read("Control").linear.x == 0.0  # stopped at the end, as a run is
