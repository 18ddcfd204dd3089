"""ROS graph names as rospy resolves them. Expected values are the tables of the ROS wiki
pages "Names" (http://wiki.ros.org/Names, section 1.1.2) and "Remapping Arguments"
(http://wiki.ros.org/Remapping%20Arguments), and rospy's client.py/names.py behaviour."""

from __future__ import annotations

import pytest

from sandbox.names import (
    InvalidName,
    Names,
    canonicalize,
    is_legal_name,
    load_mappings,
    load_private_params,
    myargv,
    namespace_of,
    resolve,
)


def node(full_name: str, argv: tuple[str, ...] = (), remaps: dict[str, str] | None = None) -> Names:
    namespace, _, base = full_name.rpartition("/")
    names = Names(argv, remaps, namespace or "/")
    names.init(base)
    assert names.node_name == full_name
    return names


# The wiki's Names table: node, name as written, resolved.
@pytest.mark.parametrize(
    ("node_name", "name", "resolved"),
    [
        ("/node1", "bar", "/bar"),
        ("/node1", "/bar", "/bar"),
        ("/node1", "~bar", "/node1/bar"),
        ("/wg/node2", "bar", "/wg/bar"),
        ("/wg/node2", "/bar", "/bar"),
        ("/wg/node2", "~bar", "/wg/node2/bar"),
        ("/wg/node3", "foo/bar", "/wg/foo/bar"),
        ("/wg/node3", "/foo/bar", "/foo/bar"),
        ("/wg/node3", "~foo/bar", "/wg/node3/foo/bar"),
        ("/wg/node3", "//foo//bar/", "/foo/bar"),  # canonical form
    ],
)
def test_names_resolve_as_the_ros_wiki_table(node_name: str, name: str, resolved: str) -> None:
    assert node(node_name).resolve(name) == resolved
    assert resolve(name, node_name) == resolved


# The wiki's Remapping Arguments table: namespace, argument, names that match, final name.
@pytest.mark.parametrize(
    ("namespace", "argument", "matching", "final"),
    [
        ("/", "foo:=bar", ("foo", "/foo"), "/bar"),
        ("/baz", "foo:=bar", ("foo", "/baz/foo"), "/baz/bar"),
        ("/baz", "/foo:=bar", ("/foo",), "/baz/bar"),
        ("/baz", "/foo:=/a/b/c/bar", ("/foo",), "/a/b/c/bar"),
    ],
)
def test_remapping_as_the_ros_wiki_table(
    namespace: str, argument: str, matching: tuple[str, ...], final: str
) -> None:
    names = Names([argument], None, namespace)
    names.init("node")
    for name in matching:
        assert names.resolve(name) == final
    assert names.resolve("other") == namespace.rstrip("/") + "/other"  # others untouched


def test_bus_names_have_no_leading_slash_for_root_topics() -> None:
    names = node("/follower")
    assert names.topic("/Distance") == names.topic("Distance") == "Distance"
    assert names.topic("/robot1/cmd_vel") == "robot1/cmd_vel"
    assert names.topic("~debug") == "follower/debug"
    assert names.service("reset") == "reset"


def test_a_namespace_prefixes_relative_topics_only() -> None:
    names = Names([], None, "/robot1")
    names.init("follower")
    assert names.topic("cmd_vel") == "robot1/cmd_vel"
    assert names.topic("/cmd_vel") == "cmd_vel"
    assert names.param("~speed") == "/robot1/follower/speed"
    assert names.param("gain") == "/robot1/gain"


def test_launch_remaps_win_over_argv_and_apply_to_topics_services_and_params() -> None:
    names = Names(["scan:=argv_scan"], {"scan": "base_scan", "reset": "/reset_all"}, "/")
    names.init("n")
    assert names.topic("scan") == "base_scan"
    assert names.service("reset") == "reset_all"
    remapped = Names(["max_speed:=/limits/speed"], None, "/")
    remapped.init("n")
    assert remapped.param("max_speed") == "/limits/speed"


def test_double_underscore_name_overrides_init_node_and_anonymous() -> None:
    names = Names(["__name:=left_wheel"], None, "/")
    assert names.init("wheel", anonymous=True) == "/left_wheel"


def test_double_underscore_ns_overrides_the_given_namespace() -> None:
    names = Names(["__ns:=/robot2"], None, "/robot1")
    assert names.init("n") == "/robot2/n"
    assert names.topic("odom") == "robot2/odom"


def test_anonymous_names_are_deterministic_and_differ_by_node() -> None:
    first = Names([], None, "/", run_name="a").init("listener", anonymous=True)
    again = Names([], None, "/", run_name="a").init("listener", anonymous=True)
    other = Names([], None, "/", run_name="b").init("listener", anonymous=True)
    assert first == again != other
    assert first.startswith("/listener_") and len(first) > len("/listener_")


def test_private_params_from_the_command_line_are_yaml_typed() -> None:
    argv = ["_speed:=0.5", "_count:=3", "_on:=true", "_label:=fast", "_xs:=[1, 2]", "_q:='7'"]
    assert load_private_params(argv) == {
        "speed": 0.5,
        "count": 3,
        "on": True,
        "label": "fast",
        "xs": [1, 2],
        "q": "7",
    }
    names = Names(argv, None, "/")
    names.init("n")
    assert names.private_params()["~speed"] == 0.5


def test_mappings_leave_out_private_params_and_keep_special_keys() -> None:
    argv = ["scan:=base_scan", "_speed:=1", "__name:=x", "plain", "--flag", "a:=b:=c"]
    assert load_mappings(argv) == {"scan": "base_scan", "__name": "x"}
    assert myargv(["prog.py", *argv]) == ["prog.py", "plain", "--flag"]


def test_before_init_node_topics_resolve_in_the_namespace_and_private_ones_are_refused() -> None:
    names = Names(["chatter:=talk"], None, "/robot1")
    assert names.topic("chatter") == "robot1/talk"  # remapped against the stand-in name
    assert names.topic("/odom") == "odom"
    with pytest.raises(InvalidName, match=r"call rospy\.init_node"):
        names.topic("~debug")
    assert names.caller_id == "/robot1/unnamed"
    assert names.param("~x") == "/robot1/unnamed/x"  # rospy resolves params against 'unnamed'


@pytest.mark.parametrize("bad", ["my topic", "1abc", "a//b/c:d", "", "scan-front"])
def test_invalid_topic_names_get_a_sentence(bad: str) -> None:
    with pytest.raises(InvalidName, match=r"valid ROS topic name|non-empty"):
        node("/n").topic(bad)


@pytest.mark.parametrize(
    ("bad", "match"),
    [
        ("/abs", "namespaces are not allowed"),
        ("a/b", "namespaces"),
        ("2fast", "not a valid ROS node name"),
        ("", "needs a node name"),
    ],
)
def test_invalid_node_names_are_refused_as_rospy_does(bad: str, match: str) -> None:
    with pytest.raises(InvalidName, match=match):
        Names().init(bad)


def test_canonical_and_namespace_helpers() -> None:
    assert canonicalize("//a//b/") == "/a/b"
    assert canonicalize("a/b/") == "a/b"
    assert namespace_of("/wg/node1") == "/wg/"
    assert namespace_of("/node") == "/"
    assert is_legal_name("~a/b") and not is_legal_name("a b") and not is_legal_name("a//b")


def test_an_invalid_remapping_is_refused() -> None:
    with pytest.raises(InvalidName, match="remapping"):
        Names([], {"scan": "bad name"}, "/")
