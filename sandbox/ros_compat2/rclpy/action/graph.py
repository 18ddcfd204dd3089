"""rclpy.action.graph: the actions of the run's graph, read off rcl_action's topics (an action
`<name>` has `<name>/_action/feedback`, typed `<pkg>/action/<Action>_FeedbackMessage`).

As rclpy/action/graph.py: get_action_names_and_types(node) -> [(name, [type])]. The two
by-node queries need the graph per node, which a RoboDojo node is not told; they say so.
"""

from __future__ import annotations

from typing import Any

_FEEDBACK = "/_action/feedback"
_SUFFIX = "_FeedbackMessage"


def get_action_names_and_types(node: Any) -> list[tuple[str, list[str]]]:
    """Every action of the run (served or asked for) with its type, e.g.
    [('/fibonacci', ['example_interfaces/action/Fibonacci'])]."""
    found: list[tuple[str, list[str]]] = []
    for topic, types in node.get_topic_names_and_types():
        if topic.endswith(_FEEDBACK):
            action_types = sorted({t.removesuffix(_SUFFIX) for t in types})
            found.append((topic.removesuffix(_FEEDBACK), action_types))
    return sorted(found)


def _per_node(what: str) -> Any:
    def query(node: Any, remote_node_name: str, remote_node_namespace: str) -> Any:
        raise NotImplementedError(
            f"rclpy.action.{what}() is not available in RoboDojo: a node is not told which "
            "node serves what; rclpy.action.get_action_names_and_types(node) lists the run's "
            "actions"
        )

    query.__name__ = what
    return query


get_action_client_names_and_types_by_node = _per_node("get_action_client_names_and_types_by_node")
get_action_server_names_and_types_by_node = _per_node("get_action_server_names_and_types_by_node")
