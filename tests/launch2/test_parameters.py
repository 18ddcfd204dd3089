"""ROS 2 parameter files and which of their rules reach a node (rcl's YAML layout, rclpy's
wildcard matching and merge order), without a sandbox: these are pure functions."""

from __future__ import annotations

from textwrap import dedent

import pytest

from sandbox.launch2.errors import LaunchError
from sandbox.launch2.parameters import node_key_matches, parse_param_file, resolve


def rules_of(text: str):
    return parse_param_file(dedent(text), "config/x.yaml", None)


def test_nested_namespaces_and_dotted_names():
    rules = rules_of(
        """\
        robot1:
          controller:
            ros__parameters:
              pid: {kp: 1.0, ki: 0.1}
              topics: [scan, odom]
        /**:
          ros__parameters:
            use_sim_time: true
        """
    )
    assert rules == [
        ("robot1/controller", {"pid.kp": 1.0, "pid.ki": 0.1, "topics": ["scan", "odom"]}),
        ("/**", {"use_sim_time": True}),
    ]


@pytest.mark.parametrize(
    ("key", "fqn", "matches"),
    [
        ("talker", "/talker", True),
        ("talker", "/ns/talker", False),  # a plain name is the root namespace's node only
        ("/**", "/ns/deep/talker", True),
        ("/**/talker", "/ns/talker", True),
        ("/**/talker", "/talker", True),
        ("/*/talker", "/ns/talker", True),
        ("/*/talker", "/a/b/talker", False),
        ("/ns/*", "/ns/listener", True),
        ("/ns/*", "/other/listener", False),
    ],
)
def test_wildcards_match_as_rclpy_matches_them(key, fqn, matches):
    assert node_key_matches(key, fqn) is matches


def test_merged_by_key_in_first_appearance_order():
    # rcl merges every file into one table by node key, in the order keys first appeared:
    # the later /** value replaces the earlier one, but /talker still comes after /**.
    rules = [("/**", {"rate": 1.0}), ("talker", {"rate": 5.0}), ("/**", {"rate": 9.0})]
    assert resolve(rules, "/talker").params == {"rate": 5.0}
    assert resolve(rules, "/other").params == {"rate": 9.0}
    unknown = resolve(rules, None)
    assert (unknown.params, unknown.unmatched) == ({"rate": 9.0}, ["talker"])


@pytest.mark.parametrize(
    ("text", "problem"),
    [
        ("speed: 0.2\n", "'speed' holds a value where a node name"),
        ("- a\n- b\n", "does not start with node names"),
        ("node:\n  ros__parameters:\n    mixed: [1, a]\n", "one kind of value"),
        ("node:\n  ros__parameters:\n    empty:\n", "'empty' has no value"),
        ("node: {ros__parameters: [1]}\n", "must hold `name: value` lines"),
        ("node:\n  ros__parameters:\n   bad: [\n", r"line \d+ is not valid YAML"),
    ],
)
def test_files_that_are_not_parameter_files(text, problem):
    with pytest.raises(LaunchError, match=problem):
        rules_of(text)
