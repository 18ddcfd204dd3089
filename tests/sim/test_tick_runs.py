"""Tick runs (server/sim/tick_runs.py) against one-tick-at-a-time stepping: the same physics.

Each case drives one robot twice through the same command script, once with the ticks between
events evaluated as arrays and once tick by tick (`tick_runs=False`, the 1 kHz reference), and
holds the two to: poses and odometry within 1e-9 m (float rounding only), the same contact and
bounds events on the same tick, the same published messages at the same times (integers and
strings equal, floats within 1e-9). The scripts hit walls, push against them, reverse, spin and
leave the world, so the cut-short runs and the one-tick path between them are exercised too.
"""

import dataclasses
import math

import numpy as np
import pytest

from sandbox.msgs.geometry_msgs import Twist, Vector3
from sandbox.msgs.std_msgs import Bool, Int16
from server.sim import Pose2D, Simulation
from server.sim.motors import CrowBotFirmwareMotors, OpenCrMotors, VelocityMotors
from server.sim.registry import get_robot
from server.sim.robots.crowbot import CrowBot
from server.sim.tick_runs import SteadyRun, arc_steps, sin_over_x

POSE_TOLERANCE_M = 1e-9
VALUE_TOLERANCE = 1e-9


def twist(linear: float, angular: float) -> Twist:
    return Twist(linear=Vector3(x=linear), angular=Vector3(z=angular))


def wander_script(robot: str, seed: int, seconds: float) -> list[tuple[float, str, object]]:
    """(step length [s], topic, command) triples: a new random Twist every 0.05-0.4 s, often at
    the robot's limits or zero, steps of uneven length (not whole ticks)."""
    model = get_robot(robot)
    topic = model.velocity_topics()[0]
    rng = np.random.default_rng(seed)
    script, elapsed = [], 0.0
    while elapsed < seconds:
        kind = rng.integers(5)
        linear = float(rng.uniform(-1, 1)) * model.limits.max_linear_m_s * 1.3
        angular = float(rng.uniform(-1, 1)) * model.limits.max_angular_rad_s
        if kind == 0:
            linear, angular = model.limits.max_linear_m_s, 0.0  # full ahead, into walls
        elif kind == 1:
            linear, angular = 0.0, 0.0
        elif kind == 2:
            linear = 0.0  # spin on the spot
        step_s = float(rng.uniform(0.05, 0.4)) + 0.00037
        script.append((step_s, topic, twist(linear, angular)))
        elapsed += step_s
    return script


def assert_same_message(fast: object, reference: object, where: str) -> None:
    if isinstance(reference, np.float32):
        # A float32 field rounds the (float64) reading: one ulp apart is the same reading.
        if np.isnan(reference):
            assert np.isnan(fast), where
        else:
            assert abs(fast - reference) <= np.spacing(abs(reference)), where
    elif isinstance(reference, float):
        assert fast == pytest.approx(reference, abs=VALUE_TOLERANCE, nan_ok=True), where
    elif isinstance(reference, (list, tuple, np.ndarray)):
        assert len(fast) == len(reference), where
        for index, (a, b) in enumerate(zip(fast, reference, strict=True)):
            assert_same_message(a, b, f"{where}[{index}]")
    elif hasattr(reference, "__slots__"):
        for name in reference.__slots__:
            assert_same_message(getattr(fast, name), getattr(reference, name), f"{where}.{name}")
    else:
        assert fast == reference, where


def assert_same_state(fast: Simulation, reference: Simulation, where: str) -> None:
    a, b = fast.state, reference.state
    for name in ("pose", "odometry_pose"):
        pa, pb = getattr(a, name), getattr(b, name)
        assert (pa.x, pa.y) == pytest.approx((pb.x, pb.y), abs=POSE_TOLERANCE_M), f"{where} {name}"
        turn = math.remainder(pa.yaw - pb.yaw, 2 * math.pi)
        assert abs(turn) < POSE_TOLERANCE_M, f"{where} {name}.yaw"
    assert a.distance_travelled_m == pytest.approx(b.distance_travelled_m, abs=1e-9), where
    assert a.wheel_left_travel_rad == pytest.approx(b.wheel_left_travel_rad, abs=1e-9), where
    assert a.wheel_right_travel_rad == pytest.approx(b.wheel_right_travel_rad, abs=1e-9), where
    assert (a.wheel_left_rad_s, a.wheel_right_rad_s) == pytest.approx(
        (b.wheel_left_rad_s, b.wheel_right_rad_s), abs=1e-9
    ), where
    assert (a.linear_m_s, a.angular_rad_s) == pytest.approx(
        (b.linear_m_s, b.angular_rad_s), abs=1e-9
    ), where
    assert a.in_contact == b.in_contact, where
    assert a.contact_count == b.contact_count, where
    assert a.time_out_of_bounds_s == pytest.approx(b.time_out_of_bounds_s, abs=1e-9), where
    assert a.servo_angle_deg == pytest.approx(b.servo_angle_deg, abs=1e-9), where
    assert a.buzzer_on == b.buzzer_on, where


def drive_both(robot, world, script, spawn=None, extra=(), physics_hz=1000.0):
    """Run `script` on a tick-run simulation and on the one-tick reference; compare after
    every step. `extra`: (step index, topic, message) commands sent besides the script's.
    Returns the reference (to check the script did what the test needs)."""
    fast = Simulation(robot, world, seed=3, spawn=spawn, physics_hz=physics_hz)
    reference = Simulation(
        robot, world, seed=3, spawn=spawn, physics_hz=physics_hz, tick_runs=False
    )
    extras = {}
    for index, topic, message in extra:
        extras.setdefault(index, []).append((topic, message))
    for index, (step_s, topic, command) in enumerate(script):
        for sim in (fast, reference):
            sim.apply(topic, command)
            for extra_topic, message in extras.get(index, ()):
                sim.apply(extra_topic, message)
        got, expected = fast.step(step_s), reference.step(step_s)
        where = f"{robot} in {world}, step {index} (t = {reference.time_s:.3f} s)"
        assert [(p.topic, p.time_s) for p in got] == [(p.topic, p.time_s) for p in expected], where
        for a, b in zip(got, expected, strict=True):
            assert_same_message(a.message, b.message, f"{where} {b.topic}")
        events, expected_events = fast.drain_events(), reference.drain_events()
        assert [(e.kind, e.time_s) for e in events] == [
            (e.kind, e.time_s) for e in expected_events
        ], where
        for a, b in zip(events, expected_events, strict=True):
            assert (a.x, a.y) == pytest.approx((b.x, b.y), abs=POSE_TOLERANCE_M), where
        assert_same_state(fast, reference, where)
    return reference


@pytest.mark.parametrize(
    ("robot", "world"),
    [
        ("crowbot", "wall_approach"),
        ("crowbot", "obstacle_maze"),
        ("crop_rover", "crop_rows"),
        ("ir_scout", "obstacle_maze"),
        ("turtlebot", "office"),
        ("turtlebot3", "obstacle_maze"),
    ],
)
def test_tick_runs_give_the_one_tick_physics_and_messages(robot, world):
    reference = drive_both(robot, world, wander_script(robot, seed=len(world), seconds=12.0))
    assert reference.state.distance_travelled_m > 0.3  # it did move


@pytest.mark.parametrize(("robot", "world"), [("crowbot", "light_arena"), ("turtlebot", "office")])
def test_coarse_ticks_turn_further_and_still_agree(robot, world):
    # At 100 Hz a tick turns up to 0.03 rad: sin(x)/x is computed, not its series.
    script = wander_script(robot, seed=7, seconds=8.0)
    drive_both(robot, world, script, physics_hz=100.0)


@pytest.mark.parametrize("robot", ["crowbot", "ir_scout", "turtlebot", "turtlebot3"])
def test_hitting_and_pushing_against_a_wall_is_found_on_the_same_tick(robot):
    topic = get_robot(robot).velocity_topics()[0]
    top = get_robot(robot).limits.max_linear_m_s
    script = [(0.25, topic, twist(top, 0.0))] * 40  # 10 s full ahead: into the wall, pushing
    script += [(0.3, topic, twist(-top, 1.0))] * 5 + [(0.2, topic, twist(0.0, 2.0))] * 10
    script += [(0.25, topic, twist(top, 0.3))] * 20
    reference = drive_both(robot, "wall_approach", script)
    assert reference.state.contact_count >= 1


def test_leaving_the_world_and_coming_back_gives_the_same_bounds_events():
    spawn = Pose2D(0.05, 0.05, math.pi)  # at the corner of line_track, facing out
    script = [(0.5, "Control", twist(0.12, 0.0))] * 4 + [(0.5, "Control", twist(-0.12, 0.0))] * 6
    reference = drive_both("crowbot", "line_track", script, spawn=spawn)
    assert reference.state.time_out_of_bounds_s > 0.5


def test_servo_slew_and_buzzer_timer_add_up_over_a_run():
    script = [(0.37, "cmd_vel", twist(0.1, 0.5))] * 12
    extra = [(0, "servo_angle", Int16(data=170)), (5, "servo_angle", Int16(data=20))]
    drive_both("ir_scout", "obstacle_maze", script, extra=extra)
    script = [(0.33, "Control", twist(0.05, 0.4))] * 8
    drive_both("crowbot", "light_arena", script, extra=[(1, "Buzzer", Bool(data=True))])


@pytest.mark.parametrize(
    "motors",
    [
        CrowBotFirmwareMotors(),
        VelocityMotors(
            0.02, 0.1, max_wheel_rad_s=10.0, max_wheel_accel_rad_s2=20.0, time_constant_s=0.08
        ),
        VelocityMotors(
            0.02, 0.1, max_wheel_rad_s=10.0, max_wheel_accel_rad_s2=5.0, time_constant_s=0.0
        ),
        OpenCrMotors(0.033, 0.16, VelocityMotors(0.033, 0.16, 6.35, 40.0, 0.05)),
    ],
    ids=["crowbot-firmware", "lag-and-ramp", "ramp-only", "opencr"],
)
def test_step_many_gives_the_speeds_of_repeated_steps(motors):
    twin = type(motors)(**{f: getattr(motors, f) for f in motors.__dataclass_fields__})
    if isinstance(motors, OpenCrMotors):
        twin.wheels = VelocityMotors(0.033, 0.16, 6.35, 40.0, 0.05)
    for linear, angular, ticks in [
        (0.1, 0.0, 300),
        (-0.08, 2.0, 57),
        (0.0, 0.0, 9),
        (0.2, -1, 700),
    ]:
        motors.command(linear, angular)
        twin.command(linear, angular)
        left, right = motors.step_many(0.001, ticks)
        one_by_one = np.array([twin.step(0.001) for _ in range(ticks)])
        assert left == pytest.approx(one_by_one[:, 0], abs=1e-12)
        assert right == pytest.approx(one_by_one[:, 1], abs=1e-12)


def test_arc_steps_are_integrate_arcs_including_straight_and_coarse_ticks():
    from server.sim.kinematics import integrate_arc

    rng = np.random.default_rng(0)
    for dt in (0.001, 0.1):  # 1 kHz, and a 10 Hz tick whose half-turns need sin(x)/x itself
        speeds = rng.uniform(-1, 1, 200)
        turns = np.where(rng.random(200) < 0.3, 0.0, rng.uniform(-4, 4, 200))
        arcs = arc_steps(np.array([0.3]), speeds[None, :] * dt, turns[None, :] * dt)
        x = y = 0.0
        yaw = 0.3
        for index in range(200):
            x, y, yaw = integrate_arc(x, y, yaw, speeds[index], turns[index], dt)
            assert float(arcs.dx[0, : index + 1].sum()) == pytest.approx(x, abs=1e-12)
            assert float(arcs.dy[0, : index + 1].sum()) == pytest.approx(y, abs=1e-12)
            assert math.remainder(float(arcs.yaw_after[0, index]) - yaw, 2 * math.pi) == (
                pytest.approx(0.0, abs=1e-12)
            )
    assert sin_over_x(np.array([0.0, 1e-3, 0.5])) == pytest.approx(
        [1.0, math.sin(1e-3) / 1e-3, math.sin(0.5) / 0.5], rel=1e-15
    )


def test_open_floor_is_crossed_in_runs_not_single_ticks(monkeypatch):
    sim = Simulation("crowbot", "light_arena", seed=0)
    single = []
    one_tick = sim._tick
    monkeypatch.setattr(sim, "_tick", lambda: single.append(1) or one_tick())
    sim.apply("Control", twist(0.1, 0.5))
    sim.step(5.0)
    # 5,000 ticks; the first (no clearance known yet) and a few where a distance query renews
    # the clearance are taken one by one.
    assert len(single) < 50
    assert sim.time_s == pytest.approx(5.0)


def test_settled_wheels_take_one_arc_per_run_and_keep_contacts_exact(monkeypatch):
    # A body disc ahead of the wheels (as the TurtleBot3's) sweeps wider than the pose point
    # when spinning: the one-arc runs must use up the clearance by the disc's chords.
    offset_geometry = dataclasses.replace(CrowBot.geometry, body_offset_x_m=0.04)
    monkeypatch.setattr(CrowBot, "geometry", offset_geometry)
    kinds = []
    follow = Simulation._follow
    monkeypatch.setattr(
        Simulation, "_follow", lambda self, run: kinds.append(type(run)) or follow(self, run)
    )
    script = [(0.5, "Control", twist(0.1, 0.0))] * 30  # settles after ~1 s, then one arc a step
    script += [(0.5, "Control", twist(0.0, 2.5))] * 8  # spinning against the wall
    script += [(0.5, "Control", twist(-0.1, 0.0))] * 4 + [(0.5, "Control", twist(0.0, 0.0))] * 6
    reference = drive_both("crowbot", "wall_approach", script)
    assert reference.state.contact_count >= 1
    assert kinds.count(SteadyRun) > 20
