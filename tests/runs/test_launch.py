"""roslaunch files read into a run (server.runs.launch): each element, each substitution, and
each error with its file and line. Expected behaviour is roslaunch's (xmlloader.py, loader.py,
http://wiki.ros.org/roslaunch/XML)."""

from __future__ import annotations

import textwrap

import pytest

from server.runs.launch import LaunchFileError, LaunchPlan, convert_value, load_launch

SCRIPTS = {
    "scripts/talker.py": "import rospy\n",
    "scripts/listener.py": "import rospy\n# listener\n",
}


def launch(body: str, files: dict[str, str] | None = None, **args: str) -> LaunchPlan:
    text = "<launch>\n" + textwrap.dedent(body) + "</launch>\n"
    workspace = {"launch/main.launch": text, **SCRIPTS, **(files or {})}
    return load_launch("launch/main.launch", workspace, args)


def failure(body: str, files: dict[str, str] | None = None, **args: str) -> LaunchFileError:
    with pytest.raises(LaunchFileError) as caught:
        launch(body, files, **args)
    return caught.value


def by_name(plan: LaunchPlan) -> dict[str, object]:
    return {node.name: node for node in plan.nodes}


# ----------------------------------------------------------------------- nodes
def test_a_node_is_the_workspace_file_its_type_names() -> None:
    plan = launch('<node pkg="demo" type="talker.py" name="talker" args="--rate 5 \'a b\'"/>\n')
    (node,) = plan.nodes
    assert node.name == "talker" and node.filename == "talker.py"
    assert node.code == SCRIPTS["scripts/talker.py"]
    assert node.args == ("--rate", "5", "a b", "__name:=talker")  # roslaunch adds __name
    assert node.namespace == "/" and node.remaps == ()


def test_node_ns_and_group_ns_nest() -> None:
    plan = launch(
        """
        <group ns="robot1">
          <node pkg="demo" type="talker.py" name="talker" ns="inner"/>
          <group ns="/absolute"><node pkg="demo" type="listener.py" name="listener"/></group>
        </group>
        """
    )
    nodes = by_name(plan)
    assert nodes["talker"].namespace == "/robot1/inner"
    assert nodes["listener"].namespace == "/absolute"


def test_nodes_with_one_name_in_two_namespaces_get_distinct_run_names() -> None:
    plan = launch(
        """
        <group ns="robot1"><node pkg="d" type="talker.py" name="talker"/></group>
        <group ns="robot2"><node pkg="d" type="talker.py" name="talker"/></group>
        """
    )
    assert [node.name for node in plan.nodes] == ["robot1_talker", "robot2_talker"]
    assert all(node.args[-1] == "__name:=talker" for node in plan.nodes)


def test_remaps_at_launch_group_and_node_level_and_the_closest_wins() -> None:
    plan = launch(
        """
        <remap from="chatter" to="global_chatter"/>
        <remap from="scan" to="base_scan"/>
        <group ns="g">
          <remap from="chatter" to="group_chatter"/>
          <node pkg="d" type="talker.py" name="talker">
            <remap from="cmd_vel" to="/mux/cmd_vel"/>
          </node>
        </group>
        <node pkg="d" type="listener.py" name="listener"/>
        """
    )
    nodes = by_name(plan)
    assert dict(nodes["talker"].remaps) == {
        "chatter": "group_chatter",
        "scan": "base_scan",
        "cmd_vel": "/mux/cmd_vel",
    }
    assert dict(nodes["listener"].remaps) == {"chatter": "global_chatter", "scan": "base_scan"}


def test_respawn_is_accepted_with_a_note_and_output_is_ignored() -> None:
    plan = launch('<node pkg="d" type="talker.py" name="t" respawn="true" output="screen"/>\n')
    assert len(plan.nodes) == 1
    assert any("respawn" in note and "not restarted" in note for note in plan.notes)


def test_a_package_xml_picks_the_file_among_two_of_the_same_name() -> None:
    files = {
        "src/a/package.xml": "<package><name>pkg_a</name></package>",
        "src/a/scripts/node.py": "A",
        "src/b/package.xml": "<package><name>pkg_b</name></package>",
        "src/b/scripts/node.py": "B",
    }
    plan = launch('<node pkg="pkg_b" type="node.py" name="n"/>\n', files)
    assert plan.nodes[0].code == "B"


# ----------------------------------------------------------------------- params
def test_params_global_relative_private_and_typed() -> None:
    plan = launch(
        """
        <param name="/max_speed" value="0.22"/>
        <param name="rate" value="10"/>
        <param name="use_sim" value="True"/>
        <param name="label" type="str" value="42"/>
        <param name="big" value="1_000"/>
        <param name="list" type="yaml" value="[1, 2.5, 'x']"/>
        <param name="~shared" value="7"/>
        <group ns="robot1">
          <node pkg="d" type="talker.py" name="talker">
            <param name="~speed" value="0.5"/>
            <param name="gain" value="2"/>
            <param name="/global_from_node" value="g"/>
          </node>
        </group>
        """
    )
    assert plan.params == {
        "max_speed": 0.22,
        "rate": 10,
        "use_sim": True,
        "label": "42",
        "big": "1_000",  # roslaunch keeps underscores a string
        "list": [1, 2.5, "x"],
        "robot1/talker/speed": 0.5,
        "robot1/talker/gain": 2,  # a <param> inside <node> is the node's own
        "global_from_node": "g",
        "robot1/talker/shared": 7,  # a ~param before a node is that node's
    }


def test_textfile_params_read_the_workspace() -> None:
    plan = launch(
        '<param name="notes" textfile="$(find demo)/config/notes.txt"/>\n',
        {"config/notes.txt": "line 1\nline 2\n"},
    )
    assert plan.params["notes"] == "line 1\nline 2\n"


def test_rosparam_inline_file_ns_param_and_delete() -> None:
    plan = launch(
        """
        <arg name="level" default="3"/>
        <rosparam>
          pid: {kp: 1.0, ki: 0}
          waypoints: [[0, 0], [1, 1]]
        </rosparam>
        <rosparam param="gains">[1, 2, 3]</rosparam>
        <rosparam ns="limits" file="$(find demo)/config/limits.yaml"/>
        <rosparam command="delete" param="pid/ki"/>
        <node pkg="d" type="talker.py" name="talker">
          <rosparam>{speed: 0.3, mode: wall}</rosparam>
          <rosparam param="~extra" subst_value="true">$(arg level)</rosparam>
        </node>
        """,
        {"config/limits.yaml": "max_speed: 0.22\nmax_turn: 2.84\n"},
    )
    assert plan.params == {
        "pid/kp": 1.0,
        "waypoints": [[0, 0], [1, 1]],
        "gains": [1, 2, 3],
        "limits/max_speed": 0.22,
        "limits/max_turn": 2.84,
        "talker/speed": 0.3,
        "talker/mode": "wall",
        "talker/extra": 3,
    }


def test_convert_value_follows_roslaunch() -> None:
    assert convert_value("3", "auto") == 3
    assert convert_value("3.0", "auto") == 3.0
    assert convert_value("TRUE", "auto") is True
    assert convert_value("1", "bool") is True
    assert convert_value("7", "double") == 7.0
    assert convert_value("{a: 1}", "yaml") == {"a": 1}
    with pytest.raises(ValueError, match="not an int"):
        convert_value("x", "int")
    with pytest.raises(ValueError, match="unknown param type"):
        convert_value("1", "float")


# ----------------------------------------------------------------------- args and substitutions
def test_args_defaults_values_and_command_line() -> None:
    body = """
        <arg name="speed" default="0.2"/>
        <arg name="fixed" value="on"/>
        <arg name="with_listener" default="false"/>
        <param name="speed" value="$(arg speed)"/>
        <param name="fixed" value="$(arg fixed)"/>
        <node pkg="d" type="talker.py" name="talker"/>
        <node pkg="d" type="listener.py" name="listener" if="$(arg with_listener)"/>
        <node pkg="d" type="listener.py" name="other" unless="$(arg with_listener)"/>
        """
    plan = launch(body)
    assert plan.params == {"speed": 0.2, "fixed": "on"}
    assert [n.name for n in plan.nodes] == ["talker", "other"]
    plan = launch(body, speed="0.5", with_listener="true")
    assert plan.params["speed"] == 0.5
    assert [n.name for n in plan.nodes] == ["talker", "listener"]


def test_anon_dirname_find_and_optenv() -> None:
    plan = launch(
        """
        <node pkg="d" type="talker.py" name="$(anon talker)"/>
        <param name="same" value="$(anon talker)"/>
        <param name="dir" value="$(dirname)/x.yaml"/>
        <param name="pkg" value="$(find demo)/data.csv"/>
        <param name="env" value="$(optenv ROBOT_NAME burger)"/>
        """
    )
    name = plan.nodes[0].name
    assert name.startswith("talker_") and plan.params["same"] == name
    assert plan.params["dir"] == "launch/x.yaml"
    assert plan.params["pkg"] == "./data.csv"
    assert plan.params["env"] == "burger"
    assert (
        launch('<param name="a" value="$(anon x)"/>').params
        == launch('<param name="a" value="$(anon x)"/>').params
    )  # deterministic, run after run


def test_include_passes_args_and_namespace() -> None:
    files = {
        "launch/robot.launch": """<launch>
            <arg name="robot_name"/>
            <arg name="speed" default="0.1"/>
            <node pkg="d" type="talker.py" name="$(arg robot_name)">
              <param name="~speed" value="$(arg speed)"/>
            </node>
          </launch>"""
    }
    plan = launch(
        """
        <include file="$(find demo)/launch/robot.launch" ns="fleet">
          <arg name="robot_name" value="alpha"/>
        </include>
        <include file="$(dirname)/robot.launch">
          <arg name="robot_name" value="beta"/>
          <arg name="speed" value="0.4"/>
        </include>
        """,
        files,
    )
    nodes = by_name(plan)
    assert nodes["alpha"].namespace == "/fleet" and nodes["beta"].namespace == "/"
    assert plan.params == {"fleet/alpha/speed": 0.1, "beta/speed": 0.4}


def test_include_with_pass_all_args() -> None:
    files = {
        "launch/inner.launch": '<launch><arg name="x" default="1"/>'
        '<param name="x" value="$(arg x)"/></launch>'
    }
    plan = launch(
        '<arg name="x" default="5"/><arg name="y" default="2"/>'
        '<include file="launch/inner.launch" pass_all_args="true"/>\n',
        files,
    )
    assert plan.params == {"x": 5}


# ----------------------------------------------------------------------- errors, each with a line
@pytest.mark.parametrize(
    ("body", "line", "words"),
    [
        ('<node pkg="d" type="missing.py" name="m"/>', 2, "scripts/listener.py, scripts/talker"),
        ('<node pkg="d" type="talker" name="m"/>', 2, 'did you mean type="talker.py"'),
        ('<node pkg="d" type="talker.py"/>', 2, "needs a 'name'"),
        ('<node pkg="d" type="talker.py" name="bad-name"/>', 2, "must start with a letter"),
        ('<node pkg="rviz" type="rviz" name="rviz"/>', 2, "remove this node"),
        ('<node pkg="d" type="talker.py" name="t" machine="pi"/>', 2, "machine= is not"),
        ('<node pkg="d" type="talker.py" name="t" launch-prefix="gdb"/>', 2, "launch-prefix"),
        ('<node pkg="d" type="talker.py" name="t" colour="red"/>', 2, "no attribute 'colour'"),
        ('<node pkg="d" type="talker.py" name="t" args="\'open"/>', 2, "cannot be split"),
        ('<node pkg="d" type="talker.py" name="t">\n<group/></node>', 3, "cannot be inside"),
        (
            '<node pkg="d" type="talker.py" name="t"/>\n<node pkg="d" type="listener.py" '
            'name="t"/>',
            3,
            "two nodes are named '/t'",
        ),
        (
            '<include file="$(find turtlebot3_gazebo)/launch/world.launch"/>',
            2,
            "the robot and world come from the run's settings; remove this include",
        ),
        ('<include file="launch/none.launch"/>', 2, "not in the workspace"),
        ('<include file="/opt/ros/x.launch"/>', 2, "outside the workspace"),
        ('<include file="launch/main.launch"/>', 2, "includes itself"),
        ('<param name="p" command="xacro robot.urdf"/>', 2, "does not run programs"),
        ('<param name="p"/>', 2, "exactly one of value= or textfile="),
        ('<param name="p" value="x" type="int"/>', 2, "not an int"),
        ('<param name="bad name" value="1"/>', 2, "not a valid parameter name"),
        ('<param name="p" textfile="none.txt"/>', 2, "not in the workspace"),
        ("<rosparam>[1, 2]</rosparam>", 2, "needs param="),
        ("<rosparam>a: [1,</rosparam>", 2, "not valid YAML"),
        ('<rosparam command="dump" file="x.yaml"/>', 2, "not done in a run"),
        ('<rosparam command="wipe"/>', 2, "load, delete or dump"),
        ('<remap from="a b" to="c"/>', 2, "not a valid ROS name"),
        ('<remap from="a"/>', 2, "needs a 'to'"),
        ('<group ns=""/>', 2, "is empty"),
        ('<env name="X" value="1"/>', 2, "<env>"),
        ('<machine name="pi" address="1.2.3.4"/>', 2, "<machine>"),
        ('<test test-name="t" pkg="d" type="talker.py"/>', 2, "rostest"),
        ("<nodes/>", 2, "not a roslaunch element"),
        ('<param name="p" value="$(arg nope)"/>', 2, "arg 'nope' is not declared"),
        ('<arg name="a"/>\n<param name="p" value="$(arg a)"/>', 3, "pass a:=VALUE"),
        ('<arg name="a" value="1" default="2"/>', 2, "both value and default"),
        ('<arg name="a" default="1"/>\n<arg name="a" default="2"/>', 3, "declared twice"),
        ('<param name="p" value="$(eval 1 + 1)"/>', 2, "$(eval ...) runs Python"),
        ('<param name="p" value="$(env HOME)"/>', 2, "no shell environment"),
        ('<param name="p" value="$(shell ls)"/>', 2, "unknown substitution"),
        ('<param name="p" value="1" if="maybe"/>', 2, "must be true, false"),
        ('<param name="p" value="1" if="true" unless="true"/>', 2, "both 'if' and 'unless'"),
        ('<node pkg="d" type="talker.py" name="t"', 3, "not well-formed XML"),
    ],
)
def test_errors_name_the_file_line_and_problem(body: str, line: int, words: str) -> None:
    error = failure(body + "\n")
    assert error.filename == "launch/main.launch"
    assert error.line == line, str(error)
    import re

    assert re.search(words if "|" in words else re.escape(words), str(error)), str(error)
    assert str(error).startswith(f"launch/main.launch, line {line}: ")


def test_errors_in_an_included_file_name_that_file() -> None:
    files = {"launch/inner.launch": '<launch>\n\n<node pkg="d" type="x.py" name="n"/></launch>'}
    error = failure('<include file="launch/inner.launch"/>\n', files)
    assert (error.filename, error.line) == ("launch/inner.launch", 3)


def test_include_arg_errors() -> None:
    files = {"launch/inner.launch": '<launch><arg name="x" default="1"/></launch>'}
    error = failure(
        '<include file="launch/inner.launch"><arg name="y" value="2"/></include>\n', files
    )
    assert "y are not declared by the included file" in str(error)
    fixed = {"launch/inner.launch": '<launch><arg name="x" value="1"/></launch>'}
    error = failure(
        '<include file="launch/inner.launch"><arg name="x" value="2"/></include>\n', fixed
    )
    assert "fixed value" in str(error)


def test_unknown_launch_arguments_are_refused_with_the_declared_ones() -> None:
    error = failure('<arg name="speed" default="1"/>\n', sped="2")
    assert "sped" in str(error) and "speed" in str(error)


def test_the_root_must_be_launch_and_the_file_must_exist() -> None:
    with pytest.raises(LaunchFileError, match="root element must be <launch>"):
        load_launch("a.launch", {"a.launch": "<robot/>"})
    with pytest.raises(LaunchFileError, match="not in the workspace"):
        load_launch("b.launch", {"a.launch": "<launch/>"})


def test_a_node_file_that_is_not_utf8_is_refused() -> None:
    workspace = {
        "x.launch": '<launch><node pkg="d" type="n.py" name="n"/></launch>',
        "n.py": b"\xff",
    }
    with pytest.raises(LaunchFileError, match="not UTF-8"):
        load_launch("x.launch", workspace)


def test_entity_declarations_are_refused() -> None:
    bomb = '<?xml version="1.0"?>\n<!DOCTYPE l [<!ENTITY a "aaaa">]>\n<launch>&a;</launch>'
    with pytest.raises(LaunchFileError, match="entity declarations") as caught:
        load_launch("a.launch", {"a.launch": bomb})
    assert caught.value.line == 2


def test_rosparam_angles_as_rosparam_reads_them() -> None:
    plan = launch(
        """
        <rosparam>
          turn: deg(90)
          half: rad(pi/2)
          full: !radians 2*pi
          back: !degrees -180
          text: degrees
        </rosparam>
        """
    )
    assert plan.params["turn"] == pytest.approx(1.5707963267948966)
    assert plan.params["half"] == pytest.approx(1.5707963267948966)
    assert plan.params["full"] == pytest.approx(6.283185307179586)
    assert plan.params["back"] == pytest.approx(-3.141592653589793)
    assert plan.params["text"] == "degrees"
    error = failure("<rosparam>a: !radians os.getcwd()</rosparam>\n")
    assert "invalid angle" in str(error) and error.line == 2
    error = failure("<rosparam>a: !!python/object:os.system x</rosparam>\n")
    assert "not valid YAML" in str(error)


def test_a_nodes_own_param_wins_over_the_scopes_private_one() -> None:
    plan = launch(
        """
        <param name="~speed" value="1"/>
        <param name="~mode" value="scope"/>
        <node pkg="d" type="talker.py" name="talker">
          <param name="speed" value="2"/>
        </node>
        <node pkg="d" type="listener.py" name="listener" required="true"/>
        """
    )
    assert plan.params == {
        "talker/speed": 2,
        "talker/mode": "scope",
        "listener/speed": 1,
        "listener/mode": "scope",
    }
    error = failure('<node pkg="d" type="talker.py" name="t" required="yes"/>\n')
    assert "'required' must be true, false" in str(error)
