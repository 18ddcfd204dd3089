"""YAML read with its aliases bounded: what a student's text can make a parser build.

An alias (`*a`) stands for the whole node its anchor (`&a`) names, so nine aliases of nine
aliases, seven levels deep, is 280 bytes of text that stands for 9^7 = 4.8 million values
("billion laughs"). PyYAML builds each alias as a second reference to one object, so loading
itself is cheap; what comes after (parameters copied into a node's settings, written to JSON,
sent to the parameter server) expands every reference, and a run worker outside the sandbox grew
by 441 MiB on that file (issue 33, finding 8). Here the composed node graph is measured first,
each distinct node once (a node's expanded size is one plus its children's, remembered), so the
measuring costs the text's size, not the expansion's; a document that would stand for more than
MAX_EXPANDED_VALUES values, or an alias inside its own anchor (a loop, which no parameter can
be), is refused with a sentence before a single object is built. Anchors that are used as
rosparam files use them (`<<: *defaults` for shared settings) stay as they were.
"""

from __future__ import annotations

from typing import Any

import yaml

# Values (scalars, lists, maps, each counted once per place it appears once aliases are expanded)
# one YAML text may stand for. The largest parameter files courses ship (a costmap with its
# plugins, a robot's full controller set) hold a few thousand; 100,000 is a 100x margin and, at
# ~100 bytes each expanded, ~10 MB: nothing a worker notices.
MAX_EXPANDED_VALUES = 100_000


class YAMLTooLarge(yaml.YAMLError):
    """A YAML text whose aliases expand past MAX_EXPANDED_VALUES, or that loops."""


def expanded_size(root: yaml.Node, budget: int = MAX_EXPANDED_VALUES) -> int:
    """The number of values `root` stands for with every alias expanded; YAMLTooLarge past
    `budget` or on an alias inside its own anchor."""
    sizes: dict[int, int] = {}  # id(node) -> expanded size, each distinct node measured once
    # Depth-first without recursion (a deep text must not reach Python's recursion limit):
    # a node is entered (its children pushed), then left (its size summed from theirs).
    entered: set[int] = set()
    stack: list[tuple[yaml.Node, bool]] = [(root, False)]
    while stack:
        node, leaving = stack.pop()
        key = id(node)
        if leaving:
            total = 1 + sum(sizes[id(child)] for child in _children(node))
            if total > budget:
                raise YAMLTooLarge(
                    f"this YAML stands for more than {budget:,} values once its aliases (*name) "
                    f"are expanded (line {node.start_mark.line + 1}): write the values out, "
                    "or use fewer aliases of aliases"
                )
            sizes[key] = total
            entered.discard(key)
            continue
        if key in sizes:
            continue
        if key in entered:
            raise YAMLTooLarge(
                f"an alias at line {node.start_mark.line + 1} is inside the anchor it names, "
                "a loop no parameter can hold: point the alias at a node outside it"
            )
        entered.add(key)
        stack.append((node, True))
        stack.extend((child, False) for child in _children(node))
    return sizes[id(root)]


def _children(node: yaml.Node) -> list[yaml.Node]:
    if isinstance(node, yaml.SequenceNode):
        return list(node.value)
    if isinstance(node, yaml.MappingNode):
        return [part for pair in node.value for part in pair]
    return []


def load(text: str, loader: type[yaml.SafeLoader] = yaml.SafeLoader) -> Any:
    """`yaml.load(text, Loader=loader)` for one document (a SafeLoader or a subclass: no Python
    objects), with its aliases bounded; YAMLTooLarge (a yaml.YAMLError) when they expand too far,
    yaml.YAMLError on bad YAML, as the loader raises it."""
    parser = loader(text)
    try:
        root = parser.get_single_node()
        if root is None:
            return None
        expanded_size(root)
        return parser.construct_document(root)
    finally:
        parser.dispose()
