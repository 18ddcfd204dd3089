"""Kinematics and motor models: exact arcs, the wheel transforms, the firmware PWM path."""

import math

import pytest

from server.sim.kinematics import body_velocities, integrate_arc, wheel_speeds, wrap_angle
from server.sim.motors import (
    CROWBOT_PWM_DEAD_BAND,
    CrowBotFirmwareMotors,
    VelocityMotors,
    crowbot_pwm,
)


def test_arc_integration_is_exact_for_any_step_size():
    # A full circle of radius 0.5 m: v = 0.5 m/s, w = 1 rad/s for 2*pi s returns to the start
    # whether taken in one step or a thousand.
    one = integrate_arc(0.0, 0.0, 0.0, 0.5, 1.0, 2 * math.pi)
    x = y = yaw = 0.0
    for _ in range(1000):
        x, y, yaw = integrate_arc(x, y, yaw, 0.5, 1.0, 2 * math.pi / 1000)
    assert one == pytest.approx((0.0, 0.0, 0.0), abs=1e-9)
    assert (x, y) == pytest.approx((0.0, 0.0), abs=1e-9)
    # A quarter circle ends at (r, r) heading +90 degrees.
    quarter = integrate_arc(0.0, 0.0, 0.0, 0.5, 1.0, math.pi / 2)
    assert quarter == pytest.approx((0.5, 0.5, math.pi / 2))


def test_straight_line_and_wrap():
    assert integrate_arc(1.0, 2.0, math.pi / 2, 0.2, 0.0, 1.0) == pytest.approx(
        (1.0, 2.2, math.pi / 2)
    )
    assert wrap_angle(3 * math.pi / 2) == pytest.approx(-math.pi / 2)
    assert wrap_angle(-math.pi) == pytest.approx(math.pi)


def test_wheel_transforms_follow_paper_eq_1_2_and_invert():
    # 000 eq. 1-2 with D = 0.04 m, d = 0.08 m: u = 0.1 m/s, w = 1 rad/s.
    left, right = wheel_speeds(0.1, 1.0, 0.02, 0.08)
    assert right == pytest.approx((2 * 0.1 + 0.08 * 1.0) / 0.04)
    assert left == pytest.approx((2 * 0.1 - 0.08 * 1.0) / 0.04)
    assert body_velocities(left, right, 0.02, 0.08) == pytest.approx((0.1, 1.0))


def test_firmware_pwm_truncates_and_clamps_like_the_c_code():
    assert crowbot_pwm(5.0) == 200  # 5 rad/s x K=40
    assert crowbot_pwm(5.024) == 200  # int() truncation, not rounding
    assert crowbot_pwm(-5.024) == -200  # toward zero for negatives, as a C cast
    assert crowbot_pwm(10.0) == 255  # 400 clamps to the 8-bit maximum
    assert crowbot_pwm(-10.0) == -255


def test_crowbot_motors_follow_within_limits_and_saturate_beyond():
    motors = CrowBotFirmwareMotors()
    motors.command(0.1, 0.0)  # 5 rad/s per wheel: PWM 200, within range
    for _ in range(1000):
        left, right = motors.step(0.001)
    assert (left, right) == pytest.approx((5.0, 5.0), rel=1e-3)
    motors.command(0.5, 0.0)  # 25 rad/s asked, PWM clamps at 255 -> 6.375 rad/s
    for _ in range(1000):
        left, right = motors.step(0.001)
    assert left == pytest.approx(255 / 40, rel=1e-3)


def test_crowbot_dead_band_leaves_slow_commands_unfollowed():
    motors = CrowBotFirmwareMotors()
    slow = (CROWBOT_PWM_DEAD_BAND - 1) / 40 * 0.02  # wheel PWM just under the dead band
    motors.command(slow, 0.0)
    for _ in range(500):
        left, right = motors.step(0.001)
    assert (left, right) == (0.0, 0.0)
    motors.command(slow * 2, 0.0)
    for _ in range(500):
        left, _ = motors.step(0.001)
    assert left > 0.0


def test_first_order_lag_reaches_63_percent_at_the_time_constant():
    motors = CrowBotFirmwareMotors()
    motors.command(0.1, 0.0)
    for _ in range(50):  # 50 ms = tau
        left, _ = motors.step(0.001)
    assert left == pytest.approx(5.0 * (1 - math.exp(-1)), rel=1e-3)


def test_velocity_motors_clamp_each_wheel_and_limit_acceleration():
    motors = VelocityMotors(
        wheel_radius_m=0.036,
        track_m=0.235,
        max_wheel_rad_s=0.5 / 0.036,
        max_wheel_accel_rad_s2=1.0 / 0.036,
        time_constant_s=0.0,
    )
    motors.command(1.0, 0.0)
    left, _ = motors.step(0.1)  # acceleration limit: 0.1 m/s after 0.1 s
    assert left * 0.036 == pytest.approx(0.1)
    for _ in range(100):
        left, right = motors.step(0.1)
    assert left * 0.036 == pytest.approx(0.5)  # per-wheel clamp at 0.5 m/s
    assert right == left  # per-wheel clamp at 0.5 m/s


def test_lag_powers_keep_one_table_per_factor_whatever_tick_counts_runs_ask_for():
    """A realtime run steps whatever tick count the wall clock gives; the powers it reads stay
    one table per lag factor (a cache per count held 256 arrays: MiB in a worker process)."""
    import tracemalloc

    import numpy as np

    from server.sim import motors

    factor = 0.998_765  # a factor no other test uses: its table starts empty
    tracemalloc.start()
    try:
        before = tracemalloc.get_traced_memory()[0]
        for ticks in range(1000, 1300):
            powers = motors._lag_powers(factor, ticks)
            assert len(powers) == ticks and not powers.flags.writeable
        held = tracemalloc.get_traced_memory()[0] - before
    finally:
        tracemalloc.stop()
    assert held < 64 * 1024, f"{held / 1024:.0f} KiB held for 300 tick counts"
    expected = factor ** np.arange(1, 1300, dtype=np.float64)
    assert np.array_equal(motors._lag_powers(factor, 1299), expected)  # bit for bit
