"""Stand-in for `launch_ros.actions`."""

from sandbox.launch2.missing import missing
from sandbox.launch2.ros_actions import (
    ComposableNodeContainer,
    LifecycleNode,
    LoadComposableNodes,
    Node,
    PushRosNamespace,
    SetParameter,
    SetParametersFromFile,
    SetRemap,
    SetUseSimTime,
)

__all__ = [
    "ComposableNodeContainer",
    "LifecycleNode",
    "LoadComposableNodes",
    "Node",
    "PushRosNamespace",
    "SetParameter",
    "SetParametersFromFile",
    "SetRemap",
    "SetUseSimTime",
]
__getattr__ = missing("launch_ros.actions")
