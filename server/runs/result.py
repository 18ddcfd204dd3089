"""How a run ended: its result (state, reason, metrics, paths) and the exception the loop raises
to end it."""

from __future__ import annotations

from dataclasses import dataclass

from server.runs.state import RunState


@dataclass
class RunResult:
    run_id: str
    state: RunState
    reason: str
    duration_s: float
    wall_s: float
    metrics: dict
    nodes: dict[str, dict]
    paths: dict[str, str]
    graph: dict
    ros_version: int = 1  # the run's ROS: 1 (rospy, step API) or 2 (rclpy)

    def summary(self) -> dict:
        """The result in one JSON-able dict, without histograms (metrics.json has them)."""
        return {
            "run_id": self.run_id,
            "state": str(self.state),
            "ros_version": self.ros_version,
            "reason": self.reason,
            "duration_s": round(self.duration_s, 6),
            "wall_s": round(self.wall_s, 3),
            "metrics": self.metrics,
            "nodes": {name: _without_histograms(node) for name, node in self.nodes.items()},
            "paths": self.paths,
        }


def _without_histograms(value: object) -> object:
    if isinstance(value, dict):
        return {k: _without_histograms(v) for k, v in value.items() if k != "histogram"}
    return value


class RunEnd(Exception):
    """Raised inside the loop to end the run: the state and the sentence that says why."""

    def __init__(self, state: RunState, reason: str) -> None:
        super().__init__(reason)
        self.state = state
        self.reason = reason
