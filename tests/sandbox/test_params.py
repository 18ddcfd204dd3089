"""The parameter server a node sees: rosmaster's tree semantics (sandbox.params) and rospy's
parameter functions on top of it (rospy/core.py), run against a stand-in node runtime (the
functions only need the node's NodeInfo and name; sandboxed runs are in test_host_rospy)."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from types import SimpleNamespace

import pytest

from sandbox import runtime
from sandbox.params import ParamNotSet, ParamServer, initial_params
from sandbox.protocol import Clock, NodeInfo
from sandbox.ros_compat import rospy
from sandbox.ros_compat.rospy import core

Activate = Callable[..., SimpleNamespace]


def make_node(
    params: dict[str, object] | None = None,
    argv: list[str] | None = None,
    remaps: dict[str, str] | None = None,
    namespace: str = "/",
) -> SimpleNamespace:
    info = NodeInfo(
        node_name="n1",
        robot="crowbot",
        robot_topics=[],
        velocity_topic=None,
        clock=Clock.LOCKSTEP,
        params=params or {},
        argv=argv or [],
        remaps=remaps or {},
        namespace=namespace,
    )
    return SimpleNamespace(info=info, node_name=None, implicit_name=False, log_level=2)


@pytest.fixture
def activate() -> Iterator[Activate]:
    def use(**kwargs: object) -> SimpleNamespace:
        node = make_node(**kwargs)  # type: ignore[arg-type]
        runtime.activate(node)  # type: ignore[arg-type]
        return node

    yield use
    runtime.activate(None)


# ----------------------------------------------------------------------- the tree
def test_a_namespace_reads_as_a_dict_and_a_dict_replaces_a_subtree() -> None:
    server = ParamServer({"/pid/kp": 1.0, "/pid/ki": 0.1, "/rate": 10})
    assert server.get("/pid") == {"kp": 1.0, "ki": 0.1}
    server.set("/pid", {"kp": 2.0, "limits": {"max": 3}})
    assert server.get("/pid") == {"kp": 2.0, "limits": {"max": 3}}
    assert not server.has("/pid/ki")  # replaced, not merged (rospy.set_param's documentation)
    assert sorted(server.names()) == ["/pid/kp", "/pid/limits/max", "/rate"]
    assert server.get("/")["rate"] == 10


def test_values_are_copies_and_tuples_come_back_as_lists() -> None:
    server = ParamServer()
    waypoints = [(1.0, 2.0), (3.0, 4.0)]
    server.set("/waypoints", waypoints)
    read = server.get("/waypoints")
    assert read == [[1.0, 2.0], [3.0, 4.0]]
    read.append("changed")
    assert server.get("/waypoints") == [[1.0, 2.0], [3.0, 4.0]]


def test_setting_below_a_value_turns_it_into_a_namespace() -> None:
    server = ParamServer({"/a": 1})
    server.set("/a/b", 2)
    assert server.get("/a") == {"b": 2}


@pytest.mark.parametrize(
    ("value", "error", "match"),
    [
        (object(), TypeError, "cannot be stored"),
        (None, TypeError, "cannot be stored"),
        (2**40, OverflowError, "32-bit"),
        ({1: "x"}, TypeError, "keys must be strings"),
    ],
)
def test_values_xmlrpc_cannot_carry_are_refused(value: object, error: type, match: str) -> None:
    with pytest.raises(error, match=match):
        ParamServer().set("/x", value)


def test_search_goes_from_the_private_namespace_up_to_the_root() -> None:
    server = ParamServer(
        {"/robot_description": "root", "/pr2/robot_description/base": "pr2", "/pr2/arm/x": 1}
    )
    # rosmaster's own example: from /pr2/foo, 'robot_description' finds /pr2/robot_description,
    # and 'robot_description/arm' is returned under it even though it is not set.
    assert server.search("/pr2/foo", "robot_description") == "/pr2/robot_description"
    assert server.search("/pr2/foo", "robot_description/arm") == "/pr2/robot_description/arm"
    assert server.search("/other/node", "robot_description") == "/robot_description"
    assert server.search("/pr2/arm", "x") == "/pr2/arm/x"  # the private namespace first
    assert server.search("/a/b", "missing") is None
    assert server.search("/a/b", "/robot_description") == "/robot_description"


def test_run_wide_names_are_global_and_tilde_names_private() -> None:
    global_params, private = initial_params({"waypoints": [1], "/g": 2, "~speed": 0.3})
    assert global_params == {"/waypoints": [1], "/g": 2}
    assert private == {"~speed": 0.3}


# ----------------------------------------------------------------------- rospy functions
def test_private_relative_and_global_names_resolve_as_rospy(activate: Activate) -> None:
    activate(
        params={"waypoints": [[0, 0]], "~speed": 0.3, "robot1/gain": 2.0},
        argv=["_mode:=fast", "_count:=4"],
        namespace="/robot1",
    )
    rospy.init_node("follower")
    assert rospy.get_name() == "/robot1/follower"
    assert rospy.get_namespace() == "/robot1/"
    assert rospy.get_param("~speed") == 0.3
    assert rospy.get_param("/robot1/follower/speed") == 0.3
    assert rospy.get_param("~mode") == "fast" and rospy.get_param("~count") == 4
    assert rospy.get_param("gain") == 2.0  # relative: in the node's namespace
    assert rospy.get_param("/waypoints") == [[0, 0]]
    assert rospy.get_param("~") == {"speed": 0.3, "mode": "fast", "count": 4}
    assert rospy.search_param("waypoints") == "/waypoints"
    assert rospy.search_param("speed") == "/robot1/follower/speed"
    assert rospy.search_param("nothing") is None


def test_a_missing_parameter_raises_key_error_naming_it_and_the_set_ones(
    activate: Activate,
) -> None:
    activate(params={"rate": 10})
    rospy.init_node("node")
    assert rospy.get_param("~missing", 5) == 5
    with pytest.raises(KeyError) as caught:
        rospy.get_param("~missing")
    message = str(caught.value)
    assert "/node/missing" in message and "'~missing'" in message and "/rate" in message
    with pytest.raises(KeyError, match="/nothing"):
        rospy.delete_param("nothing")


def test_set_has_delete_and_names(activate: Activate) -> None:
    activate()
    rospy.init_node("node")
    rospy.set_param("~pid", {"kp": 1.5, "ki": 0.0})
    rospy.set_param("/limits/speed", 0.22)
    assert rospy.has_param("~pid/kp") and rospy.has_param("/node/pid")
    assert rospy.get_param("/node/pid/kp") == 1.5
    assert sorted(rospy.get_param_names()) == ["/limits/speed", "/node/pid/ki", "/node/pid/kp"]
    rospy.delete_param("~pid")
    assert not rospy.has_param("~pid/kp")
    assert rospy.get_param_names() == ["/limits/speed"]
    with pytest.raises(TypeError, match="cannot be stored"):
        rospy.set_param("bad", object())


def test_params_before_init_node_resolve_against_unnamed_as_rospy(activate: Activate) -> None:
    activate(params={"rate": 10, "~speed": 1.0})
    assert rospy.get_name() == "/unnamed"
    assert rospy.get_param("rate") == 10
    assert not rospy.has_param("~speed")  # private parameters arrive with init_node
    rospy.init_node("node")
    assert rospy.get_param("~speed") == 1.0


def test_remapped_parameter_names(activate: Activate) -> None:
    activate(params={"limits/max_speed": 0.5}, remaps={"max_speed": "/limits/max_speed"})
    rospy.init_node("node")
    assert rospy.get_param("max_speed") == 0.5
    assert core.resolve_name("max_speed") == "/limits/max_speed"


def test_init_node_name_rules(activate: Activate) -> None:
    node = activate(argv=["__name:=from_launch"])
    rospy.init_node("talker", anonymous=True)
    assert node.node_name == "/from_launch"
    rospy.init_node("talker", anonymous=True)  # the same call again is allowed, as in rospy
    with pytest.raises(rospy.ROSException, match="already been called"):
        rospy.init_node("other")
    activate()
    with pytest.raises(ValueError, match="namespaces are not allowed"):
        rospy.init_node("/ns/name")


def test_myargv_drops_ros_arguments(monkeypatch: pytest.MonkeyPatch, activate: Activate) -> None:
    activate()
    monkeypatch.setattr("sys.argv", ["node.py", "--gain", "2", "_x:=1", "scan:=s", "__name:=n"])
    assert rospy.myargv() == ["node.py", "--gain", "2"]


def test_bad_command_line_parameters_fail_at_init_node(activate: Activate) -> None:
    activate(argv=["_x:=[unclosed"])
    with pytest.raises(rospy.ROSInitException, match="invalid command-line parameters"):
        rospy.init_node("node")


def test_a_param_not_set_error_is_a_key_error() -> None:
    assert issubclass(ParamNotSet, KeyError)
    assert str(ParamNotSet("plain sentence")) == "plain sentence"
