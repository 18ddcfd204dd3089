"""Loggers print as rclpy prints, with its levels and filters (once, throttle, skip_first)."""

from __future__ import annotations

from pathlib import Path

import pytest

from sandbox.protocol import Outcome
from tests.rclpy.harness import run


def lines(out: str) -> list[str]:
    return [line for line in out.splitlines() if line.startswith("[")]


def test_levels_filters_and_the_command_line_level(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code = """
import rclpy
from rclpy.logging import LoggingSeverity, get_logger
from rclpy.node import Node

rclpy.init()
node = Node('logger', namespace='/bot')
log = node.get_logger()
log.debug('hidden at INFO')
for i in range(5):
    log.info(f'once {i}', once=True)
    log.warning(f'skip {i}', skip_first=True)
    log.error(f'throttled {i}', throttle_duration_sec=1.0)
    rclpy.spin_once(node, timeout_sec=0.4)
log.set_level(LoggingSeverity.DEBUG)
log.debug('now shown')
child = log.get_child('planner')
child.fatal('from a child')
get_logger('free').warn('a named logger')
assert log.get_effective_level() == LoggingSeverity.DEBUG
"""
    _, exited, _ = run(code, tmp_path)
    assert exited.outcome is Outcome.FINISHED, exited.error
    assert lines(capsys.readouterr().out) == [
        "[INFO] [0.000000000] [bot.logger]: once 0",
        "[ERROR] [0.000000000] [bot.logger]: throttled 0",
        "[WARN] [0.400000000] [bot.logger]: skip 1",
        "[WARN] [0.800000000] [bot.logger]: skip 2",
        "[WARN] [1.200000000] [bot.logger]: skip 3",
        "[ERROR] [1.200000000] [bot.logger]: throttled 3",
        "[WARN] [1.600000000] [bot.logger]: skip 4",
        "[DEBUG] [2.000000000] [bot.logger]: now shown",
        "[FATAL] [2.000000000] [bot.logger.planner]: from a child",
        "[WARN] [2.000000000] [free]: a named logger",
    ]


def test_log_level_from_the_command_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code = """
import rclpy
from rclpy.node import Node
rclpy.init()
node = Node('quiet')
node.get_logger().info('not shown')
node.get_logger().error('shown')
node.get_logger().debug('not shown either')
"""
    _, exited, _ = run(code, tmp_path, argv=["--ros-args", "--log-level", "error"])
    assert exited.outcome is Outcome.FINISHED, exited.error
    assert lines(capsys.readouterr().out) == ["[ERROR] [0.000000000] [quiet]: shown"]


def test_a_logger_takes_one_string_and_says_so(tmp_path: Path) -> None:
    code = """
import rclpy
from rclpy.node import Node
rclpy.init()
Node('n').get_logger().info(42)
"""
    _, exited, _ = run(code, tmp_path)
    assert exited.outcome is Outcome.ERROR
    assert exited.error.type == "TypeError"
    assert exited.error.message.startswith("the logger prints a str, got int")
