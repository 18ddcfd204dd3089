"""A real launcher (bubblewrap sandbox, warm pool) for the launch jobs of a module, and the
ROS 2 package most tests start from: my_pkg with two nodes, a setup.py, a parameter file."""

from __future__ import annotations

import dataclasses
from textwrap import dedent

import pytest

from sandbox import bwrap
from sandbox.launcher import Launcher
from sandbox.limits import DEFAULT_LIMITS
from server.runs.launch import LaunchPlan
from server.runs.launch_py import read_launch

JOB_BUDGET_S = 6.0  # [s] a launch job reads in well under a second; a loop is stopped here


@pytest.fixture(scope="module")
def launcher():
    problem = bwrap.probe()
    if problem:
        pytest.fail(f"the launch tests need bubblewrap: {problem} (./scripts/test installs it)")
    limits = dataclasses.replace(DEFAULT_LIMITS, first_step_budget_s=JOB_BUDGET_S)
    launcher = Launcher(limits=limits, pool_size=1)
    yield launcher
    launcher.close()


PACKAGE = {
    "my_pkg/package.xml": "<package format='3'><name>my_pkg</name></package>\n",
    "my_pkg/setup.py": dedent(
        """\
        from setuptools import setup

        setup(
            name="my_pkg",
            entry_points={
                "console_scripts": [
                    "talker = my_pkg.talker:main",
                    "listener = my_pkg.listener:main",
                ],
            },
        )
        """
    ),
    "my_pkg/my_pkg/__init__.py": "",
    "my_pkg/my_pkg/talker.py": dedent(
        """\
        import rclpy
        from rclpy.node import Node


        class Talker(Node):
            def __init__(self):
                super().__init__("talker")


        def main():
            rclpy.init()
            rclpy.spin(Talker())
        """
    ),
    "my_pkg/my_pkg/listener.py": dedent(
        """\
        import rclpy


        def main():
            rclpy.init()
            rclpy.spin(rclpy.create_node("listener"))


        if __name__ == "__main__":
            main()
        """
    ),
    "my_pkg/config/params.yaml": dedent(
        """\
        /**:
          ros__parameters:
            use_sim_time: false
            rate: 1.0
        talker:
          ros__parameters:
            rate: 5.0
            pid:
              kp: 1.5
              gains: [1, 2, 3]
        robot1:
          listener:
            ros__parameters:
              topic: chatter
        """
    ),
}


def workspace(**launch_files: str) -> dict[str, str]:
    """PACKAGE plus launch files, `name="text"` -> my_pkg/launch/name.launch.py."""
    files = dict(PACKAGE)
    for name, text in launch_files.items():
        files[f"my_pkg/launch/{name}.launch.py"] = dedent(text)
    return files


def plan_of(launcher: Launcher, files: dict[str, str], name: str, **args: str) -> LaunchPlan:
    return read_launch(f"my_pkg/launch/{name}.launch.py", files, args, launcher)
