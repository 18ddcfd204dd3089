"""ROS 1 graph names for one node: resolution, remapping and rosrun's special arguments.

Behaviour follows rosgraph.names and rospy.names / rospy.client (ros/ros_comm, noetic) and the
ROS wiki pages "Names" and "Remapping Arguments" (http://wiki.ros.org/Names,
http://wiki.ros.org/Remapping%20Arguments):

- `/a/b` is global; `b` is relative to the node's namespace; `~b` is private, under the node's
  own name (`/ns/node/b`). Canonical form drops repeated and trailing slashes.
- A node's namespace comes from `__ns:=` on its command line, else its environment (here the
  launch file's `ns`, `NodeInfo.namespace`). Its name is init_node's, unless `__name:=` overrides
  it (which also turns `anonymous` off, as in rospy).
- `from:=to` arguments remap names; both sides are resolved against the node's name when it
  starts. `_param:=value` sets the private parameter `~param`, the value typed as YAML
  (rospy uses yaml.safe_load). `rospy.myargv()` drops every `name:=value` argument.
- Before init_node, topic and service names resolve against `<namespace>node` (rospy's
  resolve_name_without_node_name): relative and global ones work, private ones are refused.

The run's topic bus names root topics without the leading slash ("/Distance" -> "Distance",
"/robot1/cmd_vel" -> "robot1/cmd_vel"). Pure: no I/O.
"""

from __future__ import annotations

import re
import zlib
from collections.abc import Iterable, Mapping
from typing import Any

SEP = "/"
PRIVATE = "~"
REMAP = ":="
UNNAMED = "unnamed"  # rospy's caller id before init_node: <namespace>unnamed

_LEGAL_NAME = re.compile(r"^[~/A-Za-z][\w/]*$")
_LEGAL_BASE_NAME = re.compile(r"^[A-Za-z]\w*$")
_REMAP_ARG = re.compile(r"^([~/A-Za-z]|_|__)[\w/]*" + REMAP + ".*$", re.DOTALL)


class InvalidName(ValueError):
    """A name ROS would not accept; the message says why and what a legal one looks like."""


# ------------------------------------------------------------------ rosgraph.names look-alikes
def is_global(name: str) -> bool:
    return name.startswith(SEP)


def is_private(name: str) -> bool:
    return name.startswith(PRIVATE)


def is_legal_name(name: str) -> bool:
    """A legal graph name: a letter, `/` or `~` first, then letters, digits, `_` and `/`."""
    if name == "":
        return True
    return bool(_LEGAL_NAME.match(name)) and "//" not in name


def is_legal_base_name(name: str) -> bool:
    """A legal name without a namespace, e.g. a node name: a letter, then letters, digits, `_`."""
    return bool(_LEGAL_BASE_NAME.match(name))


def canonicalize(name: str) -> str:
    """`//a//b/` -> `/a/b`; relative names stay relative."""
    if not name or name == SEP:
        return name
    parts = [part for part in name.split(SEP) if part]
    return (SEP if name[0] == SEP else "") + SEP.join(parts)


def namespace_of(name: str) -> str:
    """The namespace holding `name`, with a trailing slash: `/wg/node1` -> `/wg/`."""
    if not name:
        return SEP
    if name.endswith(SEP):
        name = name[:-1]
    return name[: name.rfind(SEP) + 1] or SEP


def make_global_ns(name: str) -> str:
    """`foo` -> `/foo/`, `/` -> `/`: a namespace in the form names are joined to."""
    if is_private(name):
        raise InvalidName(f"'{name}' is a private (~) name and cannot be a namespace")
    if not is_global(name):
        name = SEP + name
    return name if name.endswith(SEP) else name + SEP


def ns_join(ns: str, name: str) -> str:
    """Join a namespace and a name; a global or private name is returned as it is."""
    if is_private(name) or is_global(name):
        return name
    if ns == PRIVATE:
        return PRIVATE + name
    if not ns:
        return name
    return ns + name if ns.endswith(SEP) else ns + SEP + name


def resolve(name: str, caller_id: str, remappings: Mapping[str, str] | None = None) -> str:
    """The global canonical form of `name` for the node `caller_id` (e.g. `/ns/node`)."""
    if not name:
        return namespace_of(caller_id)
    name = canonicalize(name)
    if is_global(name):
        resolved = name
    elif is_private(name):
        resolved = canonicalize(caller_id + SEP + name[1:])
    else:
        resolved = namespace_of(caller_id) + name
    if remappings and resolved in remappings:
        return remappings[resolved]
    return resolved


def check_name(name: Any, what: str = "name") -> str:
    """`name` if ROS accepts it; InvalidName with a sentence otherwise."""
    if not isinstance(name, str) or not name.strip():
        raise InvalidName(f"a {what} is a non-empty string such as 'cmd_vel', got {name!r}")
    if not is_legal_name(canonicalize(name)):
        raise InvalidName(
            f"'{name}' is not a valid ROS {what}: use letters, digits, '_' and '/' separators, "
            "starting with a letter, '/' (global) or '~' (private), e.g. 'cmd_vel', "
            "'/robot1/scan' or '~speed'"
        )
    return name


# ------------------------------------------------------------------ command-line arguments
def is_remap_arg(arg: str) -> bool:
    """True for `name:=value` arguments (remappings, `_param:=value`, `__name:=`...)."""
    return isinstance(arg, str) and bool(_REMAP_ARG.match(arg))


def load_mappings(argv: Iterable[str]) -> dict[str, str]:
    """The `from:=to` remappings (and `__name`/`__ns`...) of a command line; later ones win.
    `_param:=value` arguments are parameters, not remappings, and are left out."""
    mappings: dict[str, str] = {}
    for arg in argv:
        if not is_remap_arg(arg) or arg.count(REMAP) != 1:
            continue  # rosgraph skips `a:=b:=c` (with an error line)
        source, _, target = (part.strip() for part in arg.partition(REMAP))
        if source and target and not (len(source) > 1 and source[0] == "_" and source[1] != "_"):
            mappings[source] = target
    return mappings


def parse_param_value(text: str) -> Any:
    """A command-line parameter value typed as rospy types it (YAML: `1` int, `0.5` float,
    `true` bool, `[1, 2]` list, anything else a string)."""
    import yaml  # lazy: only nodes given `_param:=value` arguments pay for the import

    from sandbox import bounded_yaml

    try:
        return bounded_yaml.load(text)
    except yaml.YAMLError as error:
        raise InvalidName(f"cannot read the value '{text}' as YAML: {error}") from None


def load_private_params(argv: Iterable[str]) -> dict[str, Any]:
    """`_speed:=0.2` -> {"speed": 0.2}: the private parameters a command line sets."""
    params: dict[str, Any] = {}
    for arg in argv:
        if not is_remap_arg(arg):
            continue
        if arg.count(REMAP) != 1:
            raise InvalidName(f"invalid command-line parameter '{arg}': one ':=' per argument")
        source, _, target = (part.strip() for part in arg.partition(REMAP))
        if source and target and len(source) > 1 and source[0] == "_" and source[1] != "_":
            params[source[1:]] = parse_param_value(target)
    return params


def myargv(argv: Iterable[str]) -> list[str]:
    """argv without ROS's `name:=value` arguments, as rospy.myargv()."""
    return [arg for arg in argv if not is_remap_arg(arg)]


def anonymous_name(base: str, seed: str) -> str:
    """`base` with a suffix that is the same on every run (rospy's uses the pid and the wall
    clock; lockstep runs must repeat exactly)."""
    return f"{base}_{zlib.crc32(seed.encode()):08x}"


def bus_name(resolved: str) -> str:
    """The run's topic bus names root topics without their leading slash."""
    return resolved.lstrip(SEP)


# ------------------------------------------------------------------ one node's names
class Names:
    """The names of one node, as rospy resolves them: call `init()` from init_node, then
    `topic()`, `service()` and `param()` (which also work before init_node, as rospy's do)."""

    def __init__(
        self,
        argv: Iterable[str] = (),
        remaps: Mapping[str, str] | None = None,
        namespace: str = SEP,
        run_name: str = "node",
    ) -> None:
        self.argv = list(argv)
        self.run_name = run_name  # the run's label for this node: seeds anonymous names
        # A launch file passes its <remap>s on the node's command line after its args; here
        # they come separately and win over argv's, as they would there.
        self.mappings = {**load_mappings(self.argv), **dict(remaps or {})}
        for source, target in self.mappings.items():
            if source.startswith("__"):
                continue
            for side in (source, target):
                check_name(side, "name in a remapping")
        ns = self.mappings.get("__ns", namespace or SEP)
        self.namespace = make_global_ns(canonicalize(check_name(ns, "namespace")) or SEP)
        self.node_name: str | None = None
        self.resolved_mappings: dict[str, str] = {}

    @classmethod
    def from_info(cls, info: Any) -> Names:
        """From a sandbox.protocol.NodeInfo."""
        return cls(info.argv, info.remaps, info.namespace, info.node_name)

    @property
    def caller_id(self) -> str:
        """The node's full name, or `<namespace>unnamed` before init_node (as rospy)."""
        return self.node_name or self.namespace + UNNAMED

    def init(self, name: str, anonymous: bool = False, argv: Iterable[str] | None = None) -> str:
        """The node's full name for init_node(name, anonymous): `__name:=` wins (and turns
        anonymous off), then anonymous adds a deterministic suffix. Raises InvalidName."""
        if argv is not None:  # rospy: an explicit argv replaces the mapping table
            self.argv = list(argv)
            self.mappings = load_mappings(self.argv)
        if not isinstance(name, str) or not name:
            raise InvalidName(f"init_node() needs a node name such as 'follower', got {name!r}")
        if SEP in name:
            raise InvalidName(
                f"init_node({name!r}): namespaces are not allowed in node names; give a plain "
                "name such as 'follower' and set the namespace in the launch file (ns=...)"
            )
        if "__name" in self.mappings:
            name, anonymous = self.mappings["__name"], False
        if anonymous:
            name = anonymous_name(name, self.run_name)
        if not is_legal_base_name(name):
            raise InvalidName(
                f"'{name}' is not a valid ROS node name: start with a letter and use only "
                "letters, digits and '_'"
            )
        self.node_name = resolve(name, self.namespace + UNNAMED)
        self.resolved_mappings = {
            (source if source.startswith("__") else resolve(source, self.node_name)): (
                target if source.startswith("__") else resolve(target, self.node_name)
            )
            for source, target in self.mappings.items()
        }
        return self.node_name

    def private_params(self) -> dict[str, Any]:
        """The `_name:=value` parameters of the command line, as {"~name": value}."""
        return {PRIVATE + key: value for key, value in load_private_params(self.argv).items()}

    def resolve(self, name: str, what: str = "name") -> str:
        """rospy.resolve_name: the global name after remapping (before init_node, against
        `<namespace>unnamed`, with no remapping yet, as rospy)."""
        check_name(name, what)
        return resolve(name, self.caller_id, self.resolved_mappings)

    def resolve_graph_name(self, name: str, what: str) -> str:
        """A topic's or service's global name: before init_node, rospy resolves these
        against a stand-in node name and refuses private ones."""
        check_name(name, what)
        if self.node_name is None:
            return self._resolve_before_init(name, what)
        return resolve(name, self.node_name, self.resolved_mappings)

    def _resolve_before_init(self, name: str, what: str) -> str:
        if is_private(name):
            raise InvalidName(
                f"the private {what} '{name}' needs the node's name: call rospy.init_node() "
                "before creating it"
            )
        stand_in = self.namespace + "node"  # rospy resolves against a stand-in node name
        resolved = resolve(name, stand_in)
        for source, target in self.mappings.items():
            if not source.startswith("__") and resolve(source, stand_in) == resolved:
                return resolve(target, stand_in)
        return resolved

    def topic(self, name: str) -> str:
        """The bus name of a topic: resolved, remapped, without the leading slash."""
        return bus_name(self.resolve_graph_name(name, "topic name"))

    def service(self, name: str) -> str:
        """The bus name of a service, as topic()."""
        return bus_name(self.resolve_graph_name(name, "service name"))

    def param(self, name: str) -> str:
        """The absolute parameter name `/a/b` (parameter names are remapped too in rospy)."""
        if not isinstance(name, str) or not name.strip():
            raise KeyError(f"a parameter name is a non-empty string such as '~speed', got {name!r}")
        try:
            return canonicalize(self.resolve(name, "parameter name")) or SEP
        except InvalidName as error:
            raise KeyError(str(error)) from None

    def search_start(self) -> str:
        """Where search_param starts: the node's own name (its private namespace)."""
        return self.caller_id

    def myargv(self, argv: Iterable[str] | None = None) -> list[str]:
        return myargv(self.argv if argv is None else argv)
