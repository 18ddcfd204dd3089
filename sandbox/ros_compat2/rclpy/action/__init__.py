"""`rclpy.action` for student code: ActionServer and ActionClient between the nodes of a run,
wired as rcl_action wires them (see server.py and client.py), with GoalResponse and
CancelResponse for the server's callbacks."""

from .client import ActionClient, ClientGoalHandle
from .graph import (
    get_action_client_names_and_types_by_node,
    get_action_names_and_types,
    get_action_server_names_and_types_by_node,
)
from .server import ActionServer, CancelResponse, GoalResponse, ServerGoalHandle

__all__ = [
    "ActionClient",
    "ActionServer",
    "CancelResponse",
    "ClientGoalHandle",
    "GoalResponse",
    "ServerGoalHandle",
    "get_action_client_names_and_types_by_node",
    "get_action_names_and_types",
    "get_action_server_names_and_types_by_node",
]
