"""Built-in nodes: A* over the grown map, and map/pose/goal/plan reaching a student node."""

from __future__ import annotations

import numpy as np
import pytest

from sandbox.protocol import Clock
from server.runs.builtin import _grow, astar
from server.runs.commands import CommandError, Teleop
from server.runs.run import Run
from server.runs.spec import NodeSpec, RunSpec, RunSpecError
from server.runs.state import RunState


def test_astar_goes_around_a_wall_and_reports_no_path():
    blocked = np.zeros((5, 7), dtype=bool)
    blocked[0:4, 3] = True  # a wall with a gap at the bottom row
    path = astar(blocked, (0, 0), (0, 6))
    assert path[0] == (0, 0) and path[-1] == (0, 6)
    assert all(not blocked[cell] for cell in path)
    assert any(row == 4 for row, _ in path)  # it went through the gap
    blocked[4, 3] = True
    assert astar(blocked, (0, 0), (0, 6)) == []


def test_obstacles_grow_by_the_robot_radius():
    blocked = np.zeros((9, 9), dtype=bool)
    blocked[4, 4] = True
    grown = _grow(blocked, 2)
    assert grown[4, 2] and grown[2, 4] and not grown[4, 1] and not grown[2, 2]


PROBE = """
RATE_HZ = 5
SUBSCRIBE = ["map", "pose", "goal_pose", "plan"]

def step(obs):
    if obs.plan is not None:
        print("plan", len(obs.plan.poses), "goal", obs.goal_pose.pose.position.x,
              "map", obs.map.info.width, "pose", round(obs.pose.pose.position.x, 2))
    return (0.0, 0.0)
"""


def test_builtins_feed_a_student_node(tmp_path, launcher):
    spec = RunSpec(
        "turtlebot",
        "office",
        (NodeSpec("probe", PROBE, "probe.py"),),
        clock=Clock.LOCKSTEP,
        duration_s=1.0,
        spawn="start",
        builtin_nodes=("map_server", "localization", "waypoints", "planner"),
        # The first waypoint is where the robot starts: reached at once, the second follows.
        params={"waypoints": [(2.0, 1.3, 0.0), (6.0, 1.4, 0.0)]},
    )
    run = Run(spec, launcher, tmp_path / "run")
    result = run.execute()
    assert result.state is RunState.FINISHED, result.reason
    topics = {t["name"]: t for t in result.graph["topics"]}
    assert topics["goal_pose"]["messages"] == 2
    assert topics["plan"]["messages"] == 2
    assert topics["pose"]["rate_hz"] == pytest.approx(20.0, rel=0.05)
    lines = [line for line in run.slots["probe"].logs if line.startswith("plan")]
    assert lines and lines[-1].endswith("goal 6.0 map 170 pose 2.0")
    planner = run.builtins.get("planner")
    assert planner.blocked.shape == (130, 170) and planner.blocked.any()


def test_unknown_builtin_is_a_sentence():
    spec = RunSpec("crowbot", "wall_approach", (NodeSpec("n", "x = 1\n", "n.py"),),
                   builtin_nodes=("teleporter",))  # fmt: skip
    with pytest.raises(RunSpecError, match="unknown built-in node 'teleporter'"):
        spec.validate()


def test_teleop_drives_while_a_key_is_held(tmp_path, launcher):
    spec = RunSpec(
        "crowbot",
        "light_arena",
        (NodeSpec("idle", "def step(obs):\n    return None\n", "idle.py"),),
        duration_s=3.0,
        builtin_nodes=("teleop",),
        script=((0.5, Teleop("up", True)), (1.5, Teleop("up", False))),
    )
    run = Run(spec, launcher, tmp_path / "run")
    start_x = 1.0  # light_arena's centre spawn, facing +x
    result = run.execute()
    assert result.state is RunState.FINISHED, result.reason
    moved = run.sim.state.pose.x - start_x
    assert moved == pytest.approx(0.1, abs=0.015)  # 1 s at 0.1 m/s, less the motor lag
    with pytest.raises(CommandError, match="teleop knows the keys"):
        Teleop("jump", True)
