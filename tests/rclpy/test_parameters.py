"""Parameters: declared with defaults, overridden from --ros-args, a params file and the run,
typed and refused as rclpy does."""

from __future__ import annotations

from pathlib import Path

from sandbox.protocol import Outcome
from tests.rclpy.harness import published, run

REPORTER = """
import rclpy
from rclpy.node import Node
from std_msgs.msg import String

rclpy.init()
node = Node('driver')
speed = node.declare_parameter('speed', 0.2).value
name = node.declare_parameter('robot_name', 'crowbot').value
node.declare_parameters('pid', [('kp', 1.0), ('ki', 0.0)])
gains = {k: p.value for k, p in node.get_parameters_by_prefix('pid').items()}
out = node.create_publisher(String, 'report', 10)
out.publish(String(data=f'{speed!r} {name} {gains}'))
"""


def report(exited) -> list[str]:
    return [m.data for m in published([], exited, "report")]


def test_defaults_apply_without_overrides(tmp_path: Path) -> None:
    _, exited, _ = run(REPORTER, tmp_path)
    assert exited.outcome is Outcome.FINISHED, exited.error
    assert report(exited) == ["0.2 crowbot {'kp': 1.0, 'ki': 0.0}"]


def test_ros_args_override_typed_as_yaml(tmp_path: Path) -> None:
    argv = ["--ros-args", "-p", "speed:=0.35", "-p", "robot_name:=scout", "-p", "pid.kp:=2.5"]
    _, exited, _ = run(REPORTER, tmp_path, argv=argv)
    assert exited.outcome is Outcome.FINISHED, exited.error
    assert report(exited) == ["0.35 scout {'kp': 2.5, 'ki': 0.0}"]


def test_a_params_file_and_the_runs_parameters_override(tmp_path: Path) -> None:
    (tmp_path / "params.yaml").write_text(
        "/**:\n  ros__parameters:\n    speed: 0.1\n"
        "driver:\n  ros__parameters:\n    pid:\n      ki: 0.5\n"
        "other_node:\n  ros__parameters:\n    speed: 9.0\n"
    )
    argv = ["--ros-args", "--params-file", "params.yaml"]
    _, exited, _ = run(REPORTER, tmp_path, argv=argv, params={"robot_name": "from_launch"})
    assert exited.outcome is Outcome.FINISHED, exited.error
    assert report(exited) == ["0.1 from_launch {'kp': 1.0, 'ki': 0.5}"]


def test_an_integer_for_a_double_parameter_is_refused_as_ros2_refuses_it(tmp_path: Path) -> None:
    _, exited, _ = run(REPORTER, tmp_path, argv=["--ros-args", "-p", "speed:=1"])
    assert exited.outcome is Outcome.ERROR
    assert exited.error.type == "InvalidParameterTypeException"
    assert exited.error.message == (
        "Trying to set parameter 'speed' to '1' of type 'INTEGER', expecting type 'DOUBLE': speed"
    )
    assert exited.error.line == 8  # the declare_parameter line


def test_undeclared_and_twice_declared_parameters_raise_rclpys_exceptions(tmp_path: Path) -> None:
    code = """
import rclpy
from rclpy.exceptions import ParameterAlreadyDeclaredException, ParameterNotDeclaredException
from rclpy.node import Node
from std_msgs.msg import String
rclpy.init()
node = Node('n')
found = []
try:
    node.get_parameter('missing')
except ParameterNotDeclaredException as error:
    found.append(str(error))
node.declare_parameter('rate', 10)
try:
    node.declare_parameter('rate', 20)
except ParameterAlreadyDeclaredException as error:
    found.append(str(error))
found.append(str(node.has_parameter('rate')) + str(node.has_parameter('missing')))
out = node.create_publisher(String, 'report', 10)
for line in found:
    out.publish(String(data=line))
"""
    _, exited, _ = run(code, tmp_path)
    assert exited.outcome is Outcome.FINISHED, exited.error
    assert report(exited) == [
        "Invalid access to undeclared parameter(s): missing",
        "Parameter(s) already declared: ['rate']",
        "TrueFalse",
    ]


def test_set_parameters_runs_the_callback_which_may_refuse(tmp_path: Path) -> None:
    code = """
import rclpy
from rcl_interfaces.msg import SetParametersResult
from rclpy.node import Node
from rclpy.parameter import Parameter
from std_msgs.msg import String
rclpy.init()
node = Node('tuner')
node.declare_parameter('gain', 1.0)

def check(params):
    for p in params:
        if p.name == 'gain' and p.value < 0.0:
            return SetParametersResult(successful=False, reason='gain must be positive')
    return SetParametersResult(successful=True)

node.add_on_set_parameters_callback(check)
results = node.set_parameters([Parameter('gain', Parameter.Type.DOUBLE, 2.5),
                               Parameter('gain', Parameter.Type.DOUBLE, -1.0)])
out = node.create_publisher(String, 'report', 10)
for r in results:
    out.publish(String(data=f'{r.successful} {r.reason}'))
out.publish(String(data=repr(node.get_parameter('gain').value)))
value = node.get_parameter('gain').get_parameter_value()
out.publish(String(data=f'{value.type} {value.double_value}'))
"""
    _, exited, _ = run(code, tmp_path)
    assert exited.outcome is Outcome.FINISHED, exited.error
    assert report(exited) == ["True ", "False gain must be positive", "2.5", "3 2.5"]


def test_parameter_overrides_and_automatic_declaration(tmp_path: Path) -> None:
    code = """
import rclpy
from rclpy.node import Node
from rclpy.parameter import Parameter
from std_msgs.msg import String
rclpy.init()
node = Node('auto', parameter_overrides=[Parameter('mode', value='explore')],
            automatically_declare_parameters_from_overrides=True)
out = node.create_publisher(String, 'report', 10)
out.publish(String(data=node.get_parameter('mode').value))
out.publish(String(data=str(node.get_parameter('use_sim_time').value)))
"""
    _, exited, _ = run(code, tmp_path)
    assert exited.outcome is Outcome.FINISHED, exited.error
    assert report(exited) == ["explore", "False"]
