"""CreateLink: a Create on the bench as the RobotLink a hardware run drives
(server/hardware/backend.py), against the pty emulator."""

from __future__ import annotations

import time

import pytest

pytest.importorskip("serial", reason="CreateLink needs pyserial")

from sandbox.msgs.geometry_msgs import Twist, Vector3
from server.hardware.backend import HardwareRobot, RobotLost, RobotSilent
from server.hardware.create import oi
from server.hardware.create.link import CreateLink
from server.hardware.safety import MotionLimits
from tests.hardware.create_emulator import CreateEmulator
from tests.waiting import wait_until

LIMITS = MotionLimits(
    max_linear_m_s=0.3,
    max_angular_rad_s=2.0,
    max_linear_accel_m_s2=10.0,
    max_angular_accel_rad_s2=50.0,
)


def test_a_hardware_run_drives_the_create_and_reads_odom_and_bumper():
    with CreateEmulator() as emulator:
        link = CreateLink(emulator.port)
        link.open()
        try:
            robot = HardwareRobot("turtlebot", link, LIMITS)
            robot.reset()
            published = []
            end = time.monotonic() + 0.5
            while time.monotonic() < end:  # a run's loop: drive at 50 Hz for 0.5 s
                robot.apply("cmd_vel", Twist(linear=Vector3(x=0.2)))
                published += robot.step(0.02)
                time.sleep(0.02)
            robot.stop()
            wait_until(
                lambda: emulator.commands(oi.Opcode.DRIVE_DIRECT)[-1] == bytes(4),
                2,
                "the Create got the zero drive command",
            )
            frames = link.driver.stats.frames
            wait_until(
                lambda: link.driver.stats.frames >= frames + 2,
                2,
                "two sensor frames of the stopped Create reached the link",
            )
            published += robot.step(0.1)
            topics = {p.topic for p in published}
            # The robot's own topics, and what the safety layer sent beside (backend.py).
            assert topics == {"odom", "bumper", "cmd_vel_applied", "cmd_vel_limit"}
            assert emulator.commands(oi.Opcode.DRIVE_DIRECT)[-1] == bytes(4)
            odom = robot.read("odom")
            assert odom.pose.pose.position.x == pytest.approx(emulator.pose()[0], abs=0.01)
            assert odom.pose.pose.position.x > 0.05
            times = [p.time_s for p in published if p.topic in ("odom", "bumper")]
            assert times == sorted(times)
        finally:
            link.close()


def test_a_silent_create_ends_the_run_with_the_drivers_sentence():
    with CreateEmulator() as emulator:
        link = CreateLink(emulator.port, silence_timeout_s=0.1)
        link.open()
        try:
            robot = HardwareRobot("turtlebot", link, LIMITS)
            robot.reset()
            assert link.connected and link.lost_reason == ""
            emulator.go_silent()
            wait_until(lambda: not link.connected, 2, "the link noticed the silent Create")
            with pytest.raises(RobotLost, match="no sensor frame from the Create"):
                robot.step(0.02)
        finally:
            link.close()


def test_a_create_whose_stream_stops_ends_the_run_within_the_silence_bound():
    with CreateEmulator() as emulator:
        link = CreateLink(emulator.port)  # the driver's own silence timeout: 0.5 s
        link.open()
        try:
            sent = []
            send = link.send
            link.send = lambda topic, message: (sent.append(message), send(topic, message))
            robot = HardwareRobot("turtlebot", link, LIMITS)
            robot.reset()
            robot.apply("cmd_vel", Twist(linear=Vector3(x=0.2)))
            robot.step(0.02)
            robot.apply("cmd_vel", Twist(linear=Vector3(x=0.2)))
            assert sent[-1].linear.x > 0
            emulator.go_silent()
            silent_from = time.monotonic()
            with pytest.raises(RobotSilent) as ended:
                while time.monotonic() - silent_from < 2.0:
                    robot.step(0.005)
                    time.sleep(0.005)
            caught_after_s = time.monotonic() - silent_from
            assert str(ended.value) in (
                "robot stopped sending odom for 0.3 s",
                "robot stopped sending odom for 0.4 s",
            )
            assert caught_after_s < 0.45  # before the driver's own 0.5 s silence timeout
            assert link.connected  # the link still takes writes: the zero went out
            assert sent[-1] == Twist()
        finally:
            link.close()


def test_only_cmd_vel_is_taken_and_the_inbox_is_bounded():
    with CreateEmulator() as emulator:
        link = CreateLink(emulator.port, inbox_max=5)
        link.open()
        try:
            with pytest.raises(ValueError, match="takes only 'cmd_vel'"):
                link.send("Leds", object())
            frames = link.driver.stats.frames
            # Each frame brings odom and bumper: 8 frames overflow the inbox of 5.
            wait_until(
                lambda: link.driver.stats.frames >= frames + 8,
                5,
                "8 sensor frames of the Create reached the link",
            )
            taken = link.take_received()
            assert len(taken) == 5
            assert [t for t in taken if t[2] > time.monotonic()] == []
            link.drain()
            assert link.take_received() == []
        finally:
            link.close()
    assert not link.connected
    assert link.lost_reason == "the Create driver is closed"
