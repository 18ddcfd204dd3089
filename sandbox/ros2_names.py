"""ROS 2 graph names: validation, expansion and remapping, as rcl and rmw do them.

Behaviour follows rcl (ros2/rcl: src/rcl/validate_topic_name.c, expand_topic_name.c, remap.c)
and rmw (validate_node_name, validate_namespace, validate_full_topic_name), and the design
article "Topic and Service name mapping to DDS" / "Remapping Names":

- A topic name may be relative (`chatter`, joined to the node's namespace), absolute
  (`/chatter`) or private (`~/chatter`, under the node's namespace and name). `{node}` and
  `{ns}` (`{namespace}`) are substituted. Validation errors carry rcl's reason and the index of
  the offending character (rclpy prints a caret under it).
- A remap rule `[node:]from:=to` applies to a name whose expansion equals `from`'s expansion
  (against the same node); the first matching rule wins. `__node:=` (or `__name:=`) renames the
  node and `__ns:=` sets its namespace.

The run's topic bus names root topics without the leading slash (`/scan` -> `scan`), as in a
ROS 1 run. Pure: no I/O.
"""

from __future__ import annotations

from dataclasses import dataclass

SEP = "/"


class Ros2NameError(ValueError):
    """A name ROS 2 would refuse: `kind` ("topic name", "node name", "namespace", "service
    name"), rcl's `reason`, and the `index` of the character at fault."""

    def __init__(self, kind: str, name: str, reason: str, index: int) -> None:
        super().__init__(f"Invalid {kind}: {reason}:\n  '{name}'\n   {' ' * index}^")
        self.kind, self.name, self.reason, self.index = kind, name, reason, index


def _isalnum(char: str) -> bool:
    return char.isascii() and char.isalnum()


def validate_topic_name(name: str, kind: str = "topic name") -> None:
    """rcl_validate_topic_name: a name before expansion (relative, absolute or private). The
    reasons say "topic name" for services too, as rcl's do."""
    word = "topic"
    if not name:
        raise Ros2NameError(kind, name, f"{word} name must not be empty string", 0)
    if name[0].isdigit():
        raise Ros2NameError(kind, name, f"{word} name token must not start with a number", 0)
    if name.endswith(SEP):
        raise Ros2NameError(
            kind, name, f"{word} name must not end with a forward slash", len(name) - 1
        )
    in_brace, brace_at = False, 0
    for index, char in enumerate(name):
        if _isalnum(char):
            if char.isdigit() and in_brace and index - 1 == brace_at:
                raise Ros2NameError(
                    kind, name, "substitution name must not start with a number", index
                )
        elif char == "_":
            continue
        elif char == SEP:
            if in_brace:
                raise Ros2NameError(kind, name, _SUBSTITUTION_CHARS, index)
        elif char == "~":
            if index != 0:
                raise Ros2NameError(
                    kind,
                    name,
                    f"{word} name must not have tilde '~' unless it is the first character",
                    index,
                )
        elif char == "{":
            if in_brace:
                raise Ros2NameError(kind, name, _SUBSTITUTION_CHARS, index)
            in_brace, brace_at = True, index
        elif char == "}":
            if not in_brace:
                raise Ros2NameError(kind, name, _UNMATCHED.format(word=word), index)
            in_brace = False
        else:
            reason = (
                _SUBSTITUTION_CHARS
                if in_brace
                else f"{word} name must not contain characters other than alphanumerics, '_', "
                "'~', '{', or '}'"
            )
            raise Ros2NameError(kind, name, reason, index)
    if in_brace:
        raise Ros2NameError(kind, name, _UNMATCHED.format(word=word), brace_at)
    for index in range(len(name) - 1):
        if name[index] == SEP and name[index + 1].isdigit():
            raise Ros2NameError(
                kind, name, f"{word} name token must not start with a number", index + 1
            )
        if index == 1 and name[0] == "~" and name[1] != SEP:
            raise Ros2NameError(
                kind,
                name,
                f"{word} name must not have a tilde '~' that is not followed by a forward "
                "slash '/'",
                1,
            )


_SUBSTITUTION_CHARS = (
    "substitution name must not contain characters other than alphanumerics or '_'"
)
_UNMATCHED = "{word} name must not have unmatched (unbalanced) curly braces '{{}}'"


def validate_full_topic_name(name: str, kind: str = "topic name") -> None:
    """rmw_validate_full_topic_name: an expanded name (absolute, no repeated '/')."""
    word = "topic"
    if not name.startswith(SEP):
        raise Ros2NameError(kind, name, f"{word} name must be absolute, it must lead with a '/'", 0)
    double = name.find(SEP + SEP)
    if double >= 0:
        raise Ros2NameError(kind, name, f"{word} name must not contain repeated '/'", double + 1)
    validate_topic_name(name, kind)


def validate_node_name(name: str) -> None:
    """rmw_validate_node_name."""
    kind = "node name"
    if not name:
        raise Ros2NameError(kind, name, "node name must not be empty", 0)
    for index, char in enumerate(name):
        if not (_isalnum(char) or char == "_"):
            raise Ros2NameError(
                kind,
                name,
                "node name must not contain characters other than alphanumerics or '_'",
                index,
            )
    if name[0].isdigit():
        raise Ros2NameError(kind, name, "node name must not start with a number", 0)


def normalize_namespace(namespace: str | None) -> str:
    """What rcl_node_init makes of a namespace: '' -> '/', 'ns' -> '/ns'; then validated."""
    namespace = namespace or SEP
    if not namespace.startswith(SEP):
        namespace = SEP + namespace
    validate_namespace(namespace)
    return namespace


def validate_namespace(namespace: str) -> None:
    """rmw_validate_namespace (absolute; no trailing or repeated '/')."""
    kind = "namespace"
    if namespace == SEP:
        return
    if not namespace.startswith(SEP):
        raise Ros2NameError(
            kind, namespace, "namespace must be absolute, it must lead with a '/'", 0
        )
    if namespace.endswith(SEP):
        raise Ros2NameError(
            kind,
            namespace,
            "namespace must not end with a '/', unless only a '/'",
            len(namespace) - 1,
        )
    for index, char in enumerate(namespace):
        if not (_isalnum(char) or char in "_/"):
            raise Ros2NameError(
                kind,
                namespace,
                "namespace must not contain characters other than alphanumerics, '_', or '/'",
                index,
            )
        if char == SEP and index + 1 < len(namespace):
            following = namespace[index + 1]
            if following == SEP:
                raise Ros2NameError(
                    kind, namespace, "namespace must not contain repeated '/'", index + 1
                )
            if following.isdigit():
                raise Ros2NameError(
                    kind, namespace, "namespace token must not start with a number", index + 1
                )


def expand_topic_name(name: str, node_name: str, namespace: str, kind: str = "topic name") -> str:
    """rcl_expand_topic_name: the absolute name `name` stands for in node `node_name` of
    `namespace`; validated before and after (Ros2NameError)."""
    validate_topic_name(name, kind)
    ns = namespace.rstrip(SEP)
    expanded = name
    if expanded.startswith("~"):
        expanded = f"{ns}/{node_name}" + expanded[1:]
    for key, value in (("{node}", node_name), ("{ns}", ns or SEP), ("{namespace}", ns or SEP)):
        expanded = expanded.replace(key, value)
    if "{" in expanded:
        start = name.index("{")
        unknown = name[start : name.index("}", start) + 1]
        raise Ros2NameError(kind, name, f"unknown substitution: {unknown}", start)
    if not expanded.startswith(SEP):
        expanded = f"{ns}/{expanded}"
    validate_full_topic_name(expanded, kind)
    return expanded


@dataclass(frozen=True)
class RemapRule:
    """One `[node:]from:=to` rule (rcl_remap_t). `source` "__node"/"__name"/"__ns" are the
    node-name and namespace rules."""

    source: str
    target: str
    node: str | None = None  # only for the node of this name

    @classmethod
    def parse(cls, text: str) -> RemapRule:
        """A rule as written after `-r`; ValueError with a sentence when it is not one."""
        source, separator, target = text.partition(":=")
        if not separator or not source or not target or ":=" in target:
            raise ValueError(
                f"'{text}' is not a remapping rule: write FROM:=TO, e.g. -r cmd_vel:=/robot/cmd_vel"
            )
        node = None
        if ":" in source:
            node, _, source = source.partition(":")
            validate_node_name(node)
        if source not in ("__node", "__name", "__ns"):
            validate_topic_name(source, "remap rule's FROM name")
            validate_topic_name(target, "remap rule's TO name")
        return cls(source, target, node)

    def applies_to(self, node_name: str) -> bool:
        return self.node is None or self.node == node_name


def node_name_and_namespace(
    rules: list[RemapRule], node_name: str, namespace: str
) -> tuple[str, str]:
    """The node's name and namespace after `__node`/`__ns` rules (the first that applies)."""
    for rule in rules:
        if rule.source in ("__node", "__name") and rule.applies_to(node_name):
            validate_node_name(rule.target)
            node_name = rule.target
            break
    for rule in rules:
        if rule.source == "__ns" and rule.applies_to(node_name):
            namespace = normalize_namespace(rule.target)
            break
    return node_name, namespace


def remap_topic_name(rules: list[RemapRule], expanded: str, node_name: str, namespace: str) -> str:
    """rcl_remap_topic_name: the first rule whose FROM expands to `expanded` gives its TO."""
    for rule in rules:
        if rule.source.startswith("__") or not rule.applies_to(node_name):
            continue
        if expand_topic_name(rule.source, node_name, namespace) == expanded:
            return expand_topic_name(rule.target, node_name, namespace)
    return expanded


def bus_name(full_name: str) -> str:
    """The run's topic bus names root topics without their leading slash."""
    return full_name.lstrip(SEP)


class BusNames:
    """The names object of a ROS 2 node's runtime (sandbox.runtime.NodeRuntime.names): rclpy
    resolves every name itself and hands the runtime absolute ones, which only lose their
    leading slash here."""

    node_name: str | None = None

    def topic(self, name: str) -> str:
        return bus_name(name)

    def service(self, name: str) -> str:
        return bus_name(name)
