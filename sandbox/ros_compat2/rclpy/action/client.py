"""rclpy.action's ActionClient and ClientGoalHandle, as rclpy/action/client.py: a goal is sent
on `<action>/_action/send_goal` with a fresh uuid4 goal id; the Future of send_goal_async
completes with a ClientGoalHandle (accepted or not) when the server answers; feedback for the
goal (`_action/feedback`) goes to the feedback_callback given with it; the status topic
(`_action/status`) keeps every handle's status current; get_result_async() asks
`_action/get_result` and completes with the action's GetResult response (`.status`,
`.result`); cancel_goal_async() asks `_action/cancel_goal` (action_msgs/srv/CancelGoal).

The Futures complete while the node spins (rclpy.spin_until_future_complete(node, future), a
spin_once loop, or an executor), as in rclpy. send_goal(), get_result() and cancel_goal() wait
for their answer by spinning the node here; rclpy's wait on a threading.Event that only another
thread spinning the node can release, which a one-thread node does not have.

A get_result answer for a goal that has not ended yet (a server that answers at once rather
than when the goal ends, as rcl_action's do) is not taken for a result: the client asks again
when the status topic shows the goal ended.
"""

from __future__ import annotations

import time as _time
from typing import Any

from rclpy.task import Future
from sandbox.action_goals import GoalStatus

from . import wire


class ClientGoalHandle:
    """A goal as its client sees it: accepted?, status, and its result and cancel requests."""

    def __init__(self, action_client: ActionClient, goal_id: Any, goal_response: Any) -> None:
        self._action_client = action_client
        self._goal_id = goal_id
        self._goal_response = goal_response
        self._status = int(GoalStatus.UNKNOWN)

    def __eq__(self, other: object) -> bool:
        return isinstance(other, ClientGoalHandle) and wire.uuid_bytes(
            self._goal_id
        ) == wire.uuid_bytes(other._goal_id)

    def __hash__(self) -> int:
        return hash(wire.uuid_bytes(self._goal_id))

    def __repr__(self) -> str:
        return (
            f"ClientGoalHandle <id={list(bytearray(wire.uuid_bytes(self._goal_id)))}, "
            f"accepted={self.accepted}, status={self.status}>"
        )

    @property
    def goal_id(self) -> Any:
        return self._goal_id

    @property
    def stamp(self) -> Any:
        return self._goal_response.stamp

    @property
    def accepted(self) -> bool:
        return bool(self._goal_response.accepted)

    @property
    def status(self) -> int:
        return self._status

    def cancel_goal(self) -> Any:
        """Ask the server to cancel the goal and wait for its CancelGoal response."""
        return self._action_client._cancel_goal(self)

    def cancel_goal_async(self) -> Future:
        """A Future of the server's CancelGoal response."""
        return self._action_client._cancel_goal_async(self)

    def get_result(self) -> Any:
        """Wait for the goal's result (the action's GetResult response: .status, .result)."""
        return self._action_client._get_result(self)

    def get_result_async(self) -> Future:
        """A Future that completes with the GetResult response when the goal has ended."""
        return self._action_client._get_result_async(self)


class _ResultRequest:
    """One get_result_async() in progress: its Future and whether a request is in flight."""

    def __init__(self, goal_handle: ClientGoalHandle) -> None:
        self.goal_handle = goal_handle
        self.future = Future()
        self.in_flight = False


class ActionClient:
    """ActionClient(node, action_type, action_name)."""

    def __init__(
        self,
        node: Any,
        action_type: Any,
        action_name: str,
        *,
        callback_group: Any = None,
        goal_service_qos_profile: Any = None,
        result_service_qos_profile: Any = None,
        cancel_service_qos_profile: Any = None,
        feedback_sub_qos_profile: Any = None,
        status_sub_qos_profile: Any = None,
    ) -> None:
        wire.check_action_type(action_type, "ActionClient(node, action_type, name)")
        self._node = node
        self._action_type = action_type
        self._action_name = action_name
        self._logger = wire.child_logger(node, "action_client")
        names = wire.names(action_name)
        impl = action_type.Impl
        group = callback_group  # rclpy puts the whole action client in one group

        def client(srv_type: Any, name: str, qos: Any) -> Any:
            extra = {} if qos is None else {"qos_profile": qos}
            return node.create_client(srv_type, name, callback_group=group, **extra)

        self._goal_client = client(
            impl.SendGoalService, names["send_goal"], goal_service_qos_profile
        )
        self._result_client = client(
            impl.GetResultService, names["get_result"], result_service_qos_profile
        )
        self._cancel_client = client(
            impl.CancelGoalService, names["cancel_goal"], cancel_service_qos_profile
        )
        self._feedback_sub = node.create_subscription(
            impl.FeedbackMessage,
            names["feedback"],
            self._on_feedback,
            feedback_sub_qos_profile or wire.FEEDBACK_DEPTH,
            callback_group=group,
        )
        self._status_sub = node.create_subscription(
            impl.GoalStatusMessage,
            names["status"],
            self._on_status,
            status_sub_qos_profile or wire.status_qos(),
            callback_group=group,
        )
        self._goal_handles: dict[bytes, ClientGoalHandle] = {}
        self._feedback_callbacks: dict[bytes, Any] = {}
        self._result_requests: dict[bytes, _ResultRequest] = {}

    # ------------------------------------------------------------------ goals
    def _check_goal(self, goal: Any, what: str) -> None:
        if not isinstance(goal, self._action_type.Goal):
            name = getattr(self._action_type, "__name__", "the action")
            raise TypeError(
                f"{what} takes a {name}.Goal message (goal = {name}.Goal(); set its fields), "
                f"got {type(goal).__name__}"
            )

    def send_goal_async(
        self, goal: Any, feedback_callback: Any = None, goal_uuid: Any = None
    ) -> Future:
        """Send `goal`; the Future completes with a ClientGoalHandle once the server answers."""
        self._check_goal(goal, "send_goal_async()")
        request = self._action_type.Impl.SendGoalService.Request()
        request.goal_id = wire.new_goal_id() if goal_uuid is None else goal_uuid
        request.goal = goal
        key = wire.uuid_bytes(request.goal_id)
        if feedback_callback is not None:
            self._feedback_callbacks[key] = feedback_callback
        future = Future()

        def on_response(answered: Future) -> None:
            error = answered.exception()
            if error is not None:
                self._feedback_callbacks.pop(key, None)
                future.set_exception(error)
                return
            handle = ClientGoalHandle(self, request.goal_id, answered.result())
            if handle.accepted:
                if key in self._goal_handles:
                    raise RuntimeError(f"Two goals were accepted with the same ID ({handle})")
                self._goal_handles[key] = handle
            else:
                self._feedback_callbacks.pop(key, None)
            future.set_result(handle)

        self._goal_client.call_async(request).add_done_callback(on_response)
        return future

    def send_goal(self, goal: Any, feedback_callback: Any = None, goal_uuid: Any = None) -> Any:
        """Send `goal` and wait for its result (the GetResult response), spinning the node."""
        self._check_goal(goal, "send_goal()")
        handle = self._spin_until(self.send_goal_async(goal, feedback_callback, goal_uuid))
        return self._get_result(handle)  # a rejected goal's: STATUS_UNKNOWN, as in rclpy

    # ------------------------------------------------------------------ results
    def _get_result_async(self, goal_handle: ClientGoalHandle) -> Future:
        if not isinstance(goal_handle, ClientGoalHandle):
            raise TypeError(
                f"Expected type ClientGoalHandle but received {type(goal_handle).__name__}"
            )
        key = wire.uuid_bytes(goal_handle.goal_id)
        pending = self._result_requests.get(key)
        if pending is None:
            pending = self._result_requests[key] = _ResultRequest(goal_handle)
            self._ask_result(key, pending)
        return pending.future

    def _ask_result(self, key: bytes, pending: _ResultRequest) -> None:
        request = self._action_type.Impl.GetResultService.Request()
        request.goal_id = pending.goal_handle.goal_id
        pending.in_flight = True

        def on_response(answered: Future) -> None:
            pending.in_flight = False
            error = answered.exception()
            if error is not None:
                self._result_requests.pop(key, None)
                pending.future.set_exception(error)
                return
            response = answered.result()
            if response.status not in (*wire.TERMINAL, GoalStatus.UNKNOWN):
                return  # not ended yet: asked again when the status topic says it has
            self._result_requests.pop(key, None)
            self._feedback_callbacks.pop(key, None)
            pending.future.set_result(response)

        self._result_client.call_async(request).add_done_callback(on_response)

    def _get_result(self, goal_handle: ClientGoalHandle) -> Any:
        return self._spin_until(self._get_result_async(goal_handle))

    # ------------------------------------------------------------------ cancel
    def _cancel_goal_async(self, goal_handle: ClientGoalHandle) -> Future:
        if not isinstance(goal_handle, ClientGoalHandle):
            raise TypeError(
                f"Expected type ClientGoalHandle but received {type(goal_handle).__name__}"
            )
        request = self._action_type.Impl.CancelGoalService.Request()
        request.goal_info.goal_id = goal_handle.goal_id
        return self._cancel_client.call_async(request)

    def _cancel_goal(self, goal_handle: ClientGoalHandle) -> Any:
        return self._spin_until(self._cancel_goal_async(goal_handle))

    # ------------------------------------------------------------------ topics
    def _on_feedback(self, message: Any) -> None:
        callback = self._feedback_callbacks.get(wire.uuid_bytes(message.goal_id))
        if callback is not None:
            wire.run_callback(callback, message)

    def _on_status(self, message: Any) -> None:
        for entry in message.status_list:
            key = wire.uuid_bytes(entry.goal_info.goal_id)
            handle = self._goal_handles.get(key)
            if handle is not None:
                handle._status = int(entry.status)
                if entry.status in wire.TERMINAL:
                    del self._goal_handles[key]
            pending = self._result_requests.get(key)
            if pending is not None and entry.status in wire.TERMINAL and not pending.in_flight:
                self._ask_result(key, pending)

    # ------------------------------------------------------------------ server
    def server_is_ready(self) -> bool:
        """Whether an action server for this action is in the run (its three services)."""
        return all(
            client.service_is_ready()
            for client in (self._goal_client, self._result_client, self._cancel_client)
        )

    def wait_for_server(self, timeout_sec: float | None = None) -> bool:
        """Wait until an action server is there (at most `timeout_sec` seconds); whether it is."""
        deadline = None if timeout_sec is None else _time.monotonic() + float(timeout_sec)
        for client in (self._goal_client, self._result_client, self._cancel_client):
            remaining = None if deadline is None else max(0.0, deadline - _time.monotonic())
            if not client.wait_for_service(timeout_sec=remaining):
                return False
        return self.server_is_ready()

    def _spin_until(self, future: Future) -> Any:
        import rclpy

        rclpy.spin_until_future_complete(self._node, future)
        if future.exception() is not None:
            raise future.exception()
        return future.result()

    def destroy(self) -> None:
        """Stop being a client of the action."""
        for client in (self._goal_client, self._result_client, self._cancel_client):
            self._node.destroy_client(client)
        self._node.destroy_subscription(self._feedback_sub)
        self._node.destroy_subscription(self._status_sub)
