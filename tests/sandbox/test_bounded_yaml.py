"""YAML with its aliases bounded (issue 33, finding 8): a 280-byte rosparam file of 7 levels of
9 aliases grew the run worker by 441 MiB; now it is refused with a sentence before anything is
built, wherever the lab reads a student's YAML (launch files' <rosparam>, `_param:=value`,
ROS 2 parameter files and launch parameters), and ordinary YAML, anchors included, reads as
PyYAML's safe_load reads it."""

from __future__ import annotations

import resource
import time

import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from sandbox import bounded_yaml
from sandbox.bounded_yaml import YAMLTooLarge
from sandbox.names import InvalidName, parse_param_value
from server.runs.launch import LaunchFileError, load_launch


def laughs(levels: int = 7, fan_out: int = 9) -> str:
    """The issue's file: each level a list of `fan_out` aliases of the level below."""
    lines = ['a0: &a0 "lol"']
    for level in range(1, levels + 1):
        aliases = ", ".join([f"*a{level - 1}"] * fan_out)
        lines.append(f"a{level}: &a{level} [{aliases}]")
    return "\n".join(lines) + "\n"


def peak_rss_kib() -> int:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss


def test_the_issues_file_is_refused_quickly_with_a_sentence():
    text = laughs()
    assert len(text) < 400
    assert isinstance(yaml.safe_load(text)["a7"], list)  # PyYAML itself takes it (shared refs)
    started, before = time.process_time(), peak_rss_kib()
    with pytest.raises(YAMLTooLarge, match="more than 100,000 values once its aliases"):
        bounded_yaml.load(text)
    assert time.process_time() - started < 0.5  # measuring costs the text, not 4.8 M values
    assert peak_rss_kib() - before < 20 * 1024  # [KiB]: nothing near 441 MiB


def test_a_loop_through_an_alias_is_refused():
    with pytest.raises(YAMLTooLarge, match="inside the anchor it names"):
        bounded_yaml.load("a: &x [1, *x]\n")


def test_anchors_below_the_budget_read_as_safe_load_reads_them():
    text = """
defaults: &defaults {speed: 0.2, gains: [1, 2, 3]}
left:
  <<: *defaults
  side: left
right: *defaults
"""
    assert bounded_yaml.load(text) == yaml.safe_load(text)
    assert bounded_yaml.load(text)["left"] == {"speed": 0.2, "gains": [1, 2, 3], "side": "left"}
    # Just under the budget: 3 levels of 40 aliases is 1 + 40 + 40^2 + 40^3 ~ 65,641 values.
    assert len(bounded_yaml.load(laughs(levels=3, fan_out=40))["a3"]) == 40


def test_the_budget_counts_expanded_values_exactly():
    root = yaml.compose(laughs(levels=2, fan_out=3))
    # The map (1) + a0 ("lol" key and value: 2) + a1 key and its list of 3 (1 + 4) + a2 key and
    # its list of 3 lists of 3 (1 + 1 + 3 * 4).
    assert bounded_yaml.expanded_size(root) == 1 + 2 + (1 + 4) + (1 + 1 + 3 * 4)
    with pytest.raises(YAMLTooLarge):
        bounded_yaml.expanded_size(root, budget=20)


def test_empty_text_and_bad_yaml_behave_as_pyyaml_does():
    assert bounded_yaml.load("") is None
    assert bounded_yaml.load("# nothing\n") is None
    with pytest.raises(yaml.YAMLError):
        bounded_yaml.load("a: [1,\n")
    with pytest.raises(yaml.YAMLError):
        bounded_yaml.load("a: 1\n---\nb: 2\n")  # one document, as safe_load wants


yaml_values = st.recursive(
    st.none() | st.booleans() | st.integers() | st.text(max_size=8),
    lambda children: (
        st.lists(children, max_size=4) | st.dictionaries(st.text(max_size=6), children, max_size=4)
    ),
    max_leaves=20,
)


@settings(max_examples=200, deadline=None)
@given(yaml_values)
def test_any_plain_document_reads_the_same(value):
    text = yaml.safe_dump(value)
    assert bounded_yaml.load(text) == yaml.safe_load(text)


def test_a_launch_files_rosparam_bomb_is_a_sentence_naming_the_file():
    # In XML the anchors' & must be escaped; CDATA keeps the YAML as it is.
    body = "<launch>\n<rosparam><![CDATA[\n" + laughs() + "]]></rosparam>\n</launch>\n"
    with pytest.raises(LaunchFileError, match="more than 100,000 values"):
        load_launch("launch/bomb.launch", {"launch/bomb.launch": body})
    file_body = '<launch>\n<rosparam file="$(find d)/bomb.yaml"/>\n</launch>\n'
    files = {"launch/main.launch": file_body, "bomb.yaml": laughs()}
    with pytest.raises(LaunchFileError, match="more than 100,000 values"):
        load_launch("launch/main.launch", files)


def test_a_command_line_parameter_bomb_is_a_sentence():
    with pytest.raises(InvalidName, match="more than 100,000 values"):
        parse_param_value(laughs())
    assert parse_param_value("[1, 2]") == [1, 2]
