"""`robodojo run` with ROS 1 inputs: a launch file with its workspace, per-node --param /
--remap / --args as rosrun takes them, and a sentence for every bad flag."""

from __future__ import annotations

import csv
import json
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from server.cli import main
from server.cli_nodes import nodes_from_flags, read_workspace, workspace_folder
from server.runs.spec import RunSpecError

ROBODOJO = [sys.executable, "-m", "server.cli"]
BASE = ["run", "--robot", "crowbot", "--world", "wall_approach", "--duration", "3"]

TALKER = """
import rospy
import yaml
from std_msgs.msg import String

pub = rospy.Publisher("chatter", String, queue_size=10)  # before init_node, as the tutorial
rospy.init_node("talker")
greeting = rospy.get_param("~greeting")
words = yaml.safe_load(open("config/words.yaml"))["words"]  # a workspace data file
rate = rospy.Rate(rospy.get_param("/rate_hz"))
while not rospy.is_shutdown():
    pub.publish(f"{greeting} {words[0]} from {rospy.get_name()}")
    rate.sleep()
"""

LISTENER = """
import rospy
from std_msgs.msg import String

rospy.init_node("listener")
echo = rospy.Publisher("echo", String, queue_size=10)
rospy.Subscriber("conversation", String, lambda msg: echo.publish("heard: " + msg.data))
rospy.spin()
"""


def write_package(root: Path, remap: bool) -> Path:
    remap_line = '<remap from="chatter" to="conversation"/>' if remap else ""
    listener_topic = "conversation" if remap else "chatter"
    files = {
        "package.xml": "<package><name>chat</name></package>",
        "scripts/talker.py": TALKER,
        "scripts/listener.py": LISTENER.replace('"conversation"', f'"{listener_topic}"'),
        "config/words.yaml": "words: [robots]\n",
        "launch/chat.launch": f"""<launch>
              <arg name="greeting" default="hello"/>
              <param name="rate_hz" value="5"/>
              <node pkg="chat" type="talker.py" name="talker">
                <param name="~greeting" value="$(arg greeting)"/>
                {remap_line}
              </node>
              <node pkg="chat" type="listener.py" name="listener"/>
            </launch>""",
    }
    for name, text in files.items():
        path = root / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(textwrap.dedent(text))
    return root / "launch" / "chat.launch"


def robodojo(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [*ROBODOJO, *args], capture_output=True, text=True, timeout=180, check=False
    )


def topic_rows(out: Path, topic: str) -> list[dict[str, str]]:
    exported = robodojo("export", str(out))
    assert exported.returncode == 0, exported.stderr
    with open(out / "csv" / f"{topic}.csv", newline="") as stream:
        return list(csv.DictReader(stream))


def data_column(rows: list[dict[str, str]]) -> list[str]:
    (column,) = [name for name in rows[0] if name.endswith("data")]
    return [row[column] for row in rows]


@pytest.mark.slow
def test_a_launch_file_runs_two_nodes_with_a_private_param_and_a_data_file(tmp_path) -> None:
    launch = write_package(tmp_path / "chat", remap=False)
    out = tmp_path / "run"
    done = robodojo(*BASE, "--out", str(out), "--launch", str(launch), "greeting:=hi")
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout.strip().splitlines()[-1])["state"] == "finished"
    said = data_column(topic_rows(out, "chatter"))
    heard = data_column(topic_rows(out, "echo"))
    assert said and said[0] == "hi robots from /talker"
    assert heard and set(heard) == {"heard: hi robots from /talker"}
    assert 10 <= len(said) <= 16  # 5 Hz from the launch file's rate_hz for 3 s


@pytest.mark.slow
def test_a_launch_file_remap_carries_the_talk_to_the_listener(tmp_path) -> None:
    launch = write_package(tmp_path / "chat", remap=True)
    out = tmp_path / "run"
    done = robodojo(*BASE, "--out", str(out), "--launch", str(launch))
    assert done.returncode == 0, done.stderr
    heard = data_column(topic_rows(out, "echo"))
    assert heard and heard[0] == "heard: hello robots from /talker"
    assert data_column(topic_rows(out, "conversation"))


@pytest.mark.slow
def test_rosrun_style_flags_reach_the_node(tmp_path) -> None:
    node = tmp_path / "probe.py"
    node.write_text(
        textwrap.dedent(
            """
            import sys
            import rospy
            from std_msgs.msg import String

            rospy.init_node("probe")
            pub = rospy.Publisher("report", String, queue_size=10)
            values = [rospy.get_param(n) for n in ("~speed", "~mode", "/limit", "~gain")]
            rate = rospy.Rate(2)
            while not rospy.is_shutdown():
                pub.publish(repr(values) + " " + rospy.get_name())
                rate.sleep()
            """
        )
    )
    out = tmp_path / "run"
    done = robodojo(
        *BASE, "--out", str(out), "--param", "limit=[1, 2]",
        "--node", f"probe={node}", "--param", "speed=0.5", "--param", "~mode=wall",
        "--args", "_gain:=3 __name:=renamed",
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    reports = data_column(topic_rows(out, "report"))
    assert reports[0] == "[0.5, 'wall', [1, 2], 3] /renamed"


# ----------------------------------------------------------------------- mistakes, in-process
@pytest.mark.parametrize(
    ("argv", "words"),
    [
        (["--remap", "a:=b", "--node", "x.py"], "--remap applies to the node before it"),
        (["--args", "x", "--node", "x.py"], "--args applies to the node before it"),
        (["--param", "speed"], "--param takes NAME=VALUE"),
        (["--param", "bad name=1"], "not a valid ROS parameter name"),
        (["--param", "x=[1,"], "cannot read the value"),
        ([], "give the code to run"),
        (["--workspace", "."], "--workspace goes with --launch"),
        (["--launch", "nowhere.launch"], "launch file 'nowhere.launch' does not exist"),
    ],
)
def test_bad_flags_get_a_sentence_and_exit_2(
    argv: list[str], words: str, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main([*BASE, *argv]) == 2
    assert words in capsys.readouterr().err


def test_bad_remaps_and_node_flags_with_launch(tmp_path, capsys) -> None:
    node = tmp_path / "n.py"
    node.write_text("print(1)\n")
    assert main([*BASE, "--node", str(node), "--remap", "scan"]) == 2
    assert "--remap takes FROM:=TO" in capsys.readouterr().err
    assert main([*BASE, "--node", str(node), "--remap", "scan:=bad name"]) == 2
    assert "not a valid ROS name" in capsys.readouterr().err
    launch = write_package(tmp_path / "chat", remap=False)
    assert main([*BASE, "--launch", str(launch), "--node", str(node)]) == 2
    assert "--launch runs the nodes its file names" in capsys.readouterr().err
    assert main([*BASE, "--launch", str(launch), "greeting"]) == 2
    assert "launch arguments are NAME:=VALUE" in capsys.readouterr().err
    assert main([*BASE, "--launch", str(launch), "greting:=x"]) == 2
    assert "greting are not declared" in capsys.readouterr().err


def test_a_launch_file_error_names_the_file_and_line(tmp_path, capsys) -> None:
    launch = write_package(tmp_path / "chat", remap=False)
    launch.write_text('<launch>\n  <node pkg="chat" type="nope.py" name="x"/>\n</launch>\n')
    assert main([*BASE, "--launch", str(launch)]) == 2
    err = capsys.readouterr().err
    assert "launch/chat.launch, line 2: no workspace file is named 'nope.py'" in err
    assert "scripts/listener.py, scripts/talker.py" in err


def test_flags_in_order_build_nodes_and_run_params(tmp_path) -> None:
    node = tmp_path / "n.py"
    node.write_text("print(1)\n")
    nodes, params = nodes_from_flags(
        [
            ("param", "waypoints=[[0, 0], [1, 1]]"),
            ("node", f"a={node}"),
            ("param", "speed=0.2"),
            ("param", "/limit=true"),
            ("remap", "scan:=base_scan"),
            ("remap", "scan:=front_scan"),
            ("args", "--fast '_label:=a b'"),
            ("ns", "robot1"),
            ("node", f"b={node}"),
        ]
    )
    assert params == {"waypoints": [[0, 0], [1, 1]]}
    first, second = nodes
    assert first.params == {"~speed": 0.2, "/limit": True}
    assert first.remaps == (("scan", "front_scan"),)  # the later remap of a name wins
    assert first.args == ("--fast", "_label:=a b") and first.namespace == "/robot1"
    assert second.params == {} and second.remaps == () and second.namespace == "/"


def test_the_workspace_is_the_package_and_skips_what_is_not_ours(tmp_path) -> None:
    launch = write_package(tmp_path / "chat", remap=False)
    (tmp_path / "chat" / ".git").mkdir()
    (tmp_path / "chat" / ".git" / "config.txt").write_text("secret")
    (tmp_path / "chat" / "image.png").write_bytes(b"\x89PNG")
    assert workspace_folder(launch) == (tmp_path / "chat").resolve()
    files = read_workspace(tmp_path / "chat")
    assert sorted(files) == [
        "config/words.yaml",
        "launch/chat.launch",
        "package.xml",
        "scripts/listener.py",
        "scripts/talker.py",
    ]
    (tmp_path / "chat" / "big.csv").write_bytes(b"x" * (1024 * 1024 + 1))
    with pytest.raises(RunSpecError, match=r"big\.csv' is larger than"):
        read_workspace(tmp_path / "chat")
