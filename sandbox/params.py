"""A node's copy of the ROS parameter server: a tree of names, as rosmaster keeps it.

Semantics follow rosmaster's ParamDictionary (ros/ros_comm tools/rosmaster/src/rosmaster/
paramserver.py) and rospy's client API (http://wiki.ros.org/rospy/Overview/Parameter%20Server):

- Names are global here (`/a/b`); the caller resolves `~x` and `x` first (sandbox.names).
- Getting a namespace returns a dictionary of its subtree; setting a dictionary replaces the
  subtree; setting under a name that holds a value turns that value into a namespace.
- search(`/ns/node`, `key`) looks for the first part of `key` in the node's private namespace,
  then in each enclosing namespace up to the root, and returns the full name found.
- names() lists the leaves (values that are not dictionaries).
- Values are what XML-RPC carries: bool, int (32-bit), float, str, lists and dictionaries with
  string keys; tuples come back as lists. Anything else is refused with a sentence, as rospy's
  XML-RPC marshalling refuses it (rospy raises TypeError / OverflowError).

Each node has its own copy, filled from the run's parameters when it starts: set_param in one
node is not seen by the others (a run has no shared parameter server).
"""

from __future__ import annotations

import copy
from collections.abc import Mapping
from typing import Any

SEP = "/"
XMLRPC_INT_MIN, XMLRPC_INT_MAX = -(2**31), 2**31 - 1  # XML-RPC <int> is a signed 32-bit integer


class ParamNotSet(KeyError):
    """A parameter that is not set; str() is the sentence (KeyError's would add quotes)."""

    def __str__(self) -> str:
        return str(self.args[0]) if self.args else "parameter not set"


def _parts(name: str) -> list[str]:
    return [part for part in name.split(SEP) if part]


def check_value(value: Any, name: str) -> Any:
    """`value` as the parameter server would store it (tuples -> lists, deep copy), or
    TypeError/OverflowError with a sentence."""
    if isinstance(value, (bool, float, str)):
        return value
    if isinstance(value, int):
        if not XMLRPC_INT_MIN <= value <= XMLRPC_INT_MAX:
            raise OverflowError(
                f"parameter {name}: {value} does not fit the parameter server's 32-bit integers; "
                "store it as a float or a string"
            )
        return value
    if isinstance(value, (list, tuple)):
        return [check_value(item, name) for item in value]
    if isinstance(value, Mapping):
        out = {}
        for key, item in value.items():
            if not isinstance(key, str):
                raise TypeError(f"parameter {name}: dictionary keys must be strings, got {key!r}")
            out[key] = check_value(item, name + SEP + key)
        return out
    kind = type(value).__name__
    hint = " (use float(...) or int(...))" if hasattr(value, "item") else ""
    raise TypeError(
        f"parameter {name}: a {kind} cannot be stored on the parameter server{hint}; use "
        "bool, int, float, str, a list or a dict of those"
    )


class ParamServer:
    """The tree of parameters one node sees."""

    def __init__(self, initial: Mapping[str, Any] | None = None) -> None:
        self.tree: dict[str, Any] = {}
        for name, value in (initial or {}).items():
            self.set(name, value)

    def _node(self, name: str) -> Any:
        value: Any = self.tree
        for part in _parts(name):
            if not isinstance(value, dict) or part not in value:
                raise ParamNotSet(name)
            value = value[part]
        return value

    def get(self, name: str) -> Any:
        """A copy of the value (a dict for a namespace); ParamNotSet if nothing is there."""
        try:
            return copy.deepcopy(self._node(name))
        except ParamNotSet:
            raise ParamNotSet(self.missing_sentence(name)) from None

    def has(self, name: str) -> bool:
        try:
            self._node(name)
        except ParamNotSet:
            return False
        return True

    def set(self, name: str, value: Any) -> None:
        value = check_value(value, name)
        parts = _parts(name)
        if not parts:
            if not isinstance(value, dict):
                raise TypeError("only a dictionary can be set at the root '/' of the parameters")
            self.tree = value
            return
        node = self.tree
        for part in parts[:-1]:
            if not isinstance(node.get(part), dict):
                node[part] = {}  # a value becomes a namespace, as on rosmaster
            node = node[part]
        node[parts[-1]] = value

    def delete(self, name: str) -> None:
        parts = _parts(name)
        if not parts:
            raise ParamNotSet("the root '/' of the parameters cannot be deleted")
        parent = self._node(SEP + SEP.join(parts[:-1])) if parts[:-1] else self.tree
        if not isinstance(parent, dict) or parts[-1] not in parent:
            raise ParamNotSet(self.missing_sentence(name))
        del parent[parts[-1]]

    def names(self) -> list[str]:
        """Every leaf's full name."""
        found: list[str] = []

        def walk(prefix: str, node: dict[str, Any]) -> None:
            for key, value in node.items():
                if isinstance(value, dict):
                    walk(prefix + key + SEP, value)
                else:
                    found.append(prefix + key)

        walk(SEP, self.tree)
        return found

    def search(self, start: str, key: str) -> str | None:
        """The full name `key` (relative) resolves to, searching from the namespace `start`
        (a node's full name) up to the root; None if no namespace holds it."""
        if key.startswith(SEP):
            return key if self.has(key) else None
        key_parts = _parts(key)
        if not key_parts:
            return None
        namespaces = _parts(start)
        for depth in range(len(namespaces), -1, -1):
            prefix = SEP + SEP.join([*namespaces[:depth], key_parts[0]])
            if self.has(prefix):
                return SEP + SEP.join([*namespaces[:depth], *key_parts])
        return None

    def missing_sentence(self, name: str, asked: str | None = None) -> str:
        known = self.names()
        shown = ", ".join(sorted(known)[:30]) + (", ..." if len(known) > 30 else "")
        asked_part = f" (asked as '{asked}')" if asked and asked != name else ""
        return f"parameter {name}{asked_part} is not set; the parameters set: {shown or 'none'}"


def initial_params(params: Mapping[str, Any]) -> tuple[dict[str, Any], dict[str, Any]]:
    """Split a node's NodeInfo.params into (global, private): `~x` is the node's own (resolved
    once its name is known); `x` and `/x` are global (`/x`), as run-wide parameters are."""
    global_params: dict[str, Any] = {}
    private: dict[str, Any] = {}
    for name, value in params.items():
        if name.startswith("~"):
            private[name] = value
        else:
            global_params[SEP + name.lstrip(SEP)] = value
    return global_params, private
