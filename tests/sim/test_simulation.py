"""The Simulation contract: physics through the whole stack, determinism, events, bad input."""

import math

import numpy as np
import pytest

from sandbox.msgs.geometry_msgs import Twist, Vector3
from sandbox.msgs.std_msgs import Bool, Float32, Int16, Int32, Int32MultiArray, String
from server.sim import EventKind, Pose2D, Simulation, SimulationError
from server.sim.checks import registry_problems
from server.sim.registry import UnknownRobotError, get_robot, robot_ids
from server.sim.world import WorldError


def twist(linear: float = 0.0, angular: float = 0.0) -> Twist:
    return Twist(linear=Vector3(x=linear), angular=Vector3(z=angular))


def open_floor_crowbot(seed: int = 0) -> Simulation:
    # light_arena's centre has a metre of free floor in every direction.
    return Simulation("crowbot", "light_arena", seed=seed)


def test_straight_twist_moves_the_crowbot_about_a_tenth_of_a_metre():
    sim = open_floor_crowbot()
    start = Pose2D(sim.state.pose.x, sim.state.pose.y, sim.state.pose.yaw)
    sim.apply("Control", twist(0.1))
    sim.step(1.0)
    moved = math.hypot(sim.state.pose.x - start.x, sim.state.pose.y - start.y)
    # 0.1 m less the 50 ms motor lag (0.005 m).
    assert moved == pytest.approx(0.095, abs=0.003)
    assert sim.state.distance_travelled_m == pytest.approx(moved, rel=1e-6)


def test_turn_of_one_rad_per_second_for_half_pi_seconds_is_about_ninety_degrees():
    sim = open_floor_crowbot()
    yaw0 = sim.state.pose.yaw
    sim.apply("Control", twist(0.0, 1.0))
    sim.step(math.pi / 2)
    turned = math.degrees(sim.state.pose.yaw - yaw0)
    assert turned == pytest.approx(90.0, abs=4.0)  # lag costs ~3 degrees
    assert math.hypot(sim.state.pose.x - 1.0, sim.state.pose.y - 1.0) < 0.01  # turned in place


def test_crowbot_cannot_exceed_its_pwm_limit_or_crawl_below_its_dead_band():
    fast = open_floor_crowbot()
    x0 = fast.state.pose.x
    fast.apply("Control", twist(0.5))  # 25 rad/s per wheel asked, PWM clamps to 6.4 rad/s
    fast.step(1.0)
    assert fast.state.pose.x - x0 == pytest.approx(0.1275, abs=0.01)
    crawl = open_floor_crowbot()
    crawl.apply("Control", twist(0.005))  # PWM 10, under the dead band
    crawl.step(1.0)
    assert crawl.state.distance_travelled_m == 0.0


def test_wall_stops_the_robot_without_penetration_and_counts_one_contact():
    sim = Simulation("crowbot", "wall_approach", seed=0)
    sim.apply("Control", twist(0.1))
    sim.step(10.0)
    assert sim.state.contact_count == 1
    assert sim.state.in_contact
    clearance = sim.obstacles.clearance(sim.state.pose.x, sim.state.pose.y)
    assert clearance >= sim.robot.geometry.body_radius_m - 1e-6
    kinds = [event.kind for event in sim.drain_events()]
    assert kinds == [EventKind.CONTACT_BEGAN]
    sim.apply("Control", twist(-0.1))
    sim.step(1.0)
    assert not sim.state.in_contact
    assert [event.kind for event in sim.drain_events()] == [EventKind.CONTACT_ENDED]


def test_a_touch_right_after_a_release_continues_the_contact_and_a_new_approach_counts():
    # Pushed against the wall while turning, the Roomba's disc leaves the wall and touches it
    # again 95 ms later: one contact (simulation.CONTACT_DEBOUNCE_S), two raw touches.
    sim = Simulation("turtlebot", "wall_approach", seed=0)
    sim.apply("cmd_vel", twist(0.5))
    sim.step(10.0)
    sim.apply("cmd_vel", twist(0.3, 1.0))
    sim.step(2.0)
    kinds = [event.kind for event in sim.drain_events()]
    assert kinds.count(EventKind.CONTACT_BEGAN) == 2 and EventKind.CONTACT_ENDED in kinds
    assert sim.state.contact_count == 1
    # Backing off for a second and driving in again is a contact of its own.
    again = Simulation("crowbot", "wall_approach", seed=0)
    for linear, seconds in ((0.1, 10.0), (-0.1, 1.0), (0.1, 3.0)):
        again.apply("Control", twist(linear))
        again.step(seconds)
    assert again.state.in_contact and again.state.contact_count == 2


def test_sensor_topics_publish_at_their_declared_rates_in_time_order():
    sim = Simulation("turtlebot", "office", seed=3)
    published = sim.step(2.0)
    times = [item.time_s for item in published]
    assert times == sorted(times)
    for spec in sim.topics:
        if spec.rate_hz:
            count = sum(1 for item in published if item.topic == spec.name)
            assert count == pytest.approx(2.0 * spec.rate_hz, abs=1.0), spec.name


def test_many_small_steps_equal_one_big_step():
    a, b = open_floor_crowbot(seed=5), open_floor_crowbot(seed=5)
    for sim in (a, b):
        sim.apply("Control", twist(0.08, 0.7))
    big = a.step(1.0)
    small = [item for _ in range(400) for item in b.step(0.0025)]
    assert [(p.topic, p.time_s) for p in big] == [(p.topic, p.time_s) for p in small]
    assert [p.message.serialize() for p in big] == [p.message.serialize() for p in small]
    # The same ticks; a big step evaluates them in runs (server/sim/tick_runs.py), small ones
    # one by one, so the sums round differently in the last bits.
    assert (a.state.pose.x, a.state.pose.y) == pytest.approx(
        (b.state.pose.x, b.state.pose.y), abs=1e-12
    )


def _stream(robot: str, world: str, seed: int, command: tuple[str, object]) -> list[bytes]:
    sim = Simulation(robot, world, seed=seed)
    sim.apply(*command)
    return [p.topic.encode() + p.message.serialize() for p in sim.step(3.0)]


@pytest.mark.parametrize(
    ("robot", "world", "command"),
    [
        ("crowbot", "light_arena", ("Control", twist(0.05, 0.5))),
        ("crop_rover", "crop_rows", ("u", Float32(data=10.0))),
        ("ir_scout", "obstacle_maze", ("motor_command", String(data="forward"))),
        ("turtlebot", "office", ("cmd_vel", twist(0.2, 0.1))),
        ("turtlebot3", "office", ("cmd_vel", twist(0.2, 0.1))),
    ],
)
def test_same_seed_gives_identical_streams_and_another_seed_different_noise(robot, world, command):
    first = _stream(robot, world, 11, command)
    assert first == _stream(robot, world, 11, command)
    assert first != _stream(robot, world, 12, command)


def test_reset_replays_the_same_episode():
    sim = open_floor_crowbot(seed=2)
    sim.apply("Control", twist(0.1, 0.3))
    first = [p.message.serialize() for p in sim.step(1.0)]
    sim.reset()
    sim.apply("Control", twist(0.1, 0.3))
    assert [p.message.serialize() for p in sim.step(1.0)] == first


def test_button_leds_and_buzzer_are_robot_state():
    sim = open_floor_crowbot()
    sim.press_button(True)
    sim.step(0.1)
    assert sim.read("Button") == Bool(data=True)
    sim.apply("Leds", Int32MultiArray(data=[255, 0, 128]))
    sim.apply("Buzzer", Bool(data=True))
    sim.step(0.5)
    scene = sim.scene()
    assert scene.leds_rgb == (255, 0, 128)
    assert scene.buzzer_on
    sim.step(0.6)  # B4 plays for one second
    assert not sim.scene().buzzer_on


def test_ir_scout_servo_slews_to_the_commanded_angle():
    sim = Simulation("ir_scout", "obstacle_maze", seed=0)
    sim.apply("servo_angle", Int16(data=180))
    sim.step(0.1)
    assert 90.0 < sim.state.servo_angle_deg < 180.0  # still moving: 500 deg/s
    sim.step(0.2)
    assert sim.state.servo_angle_deg == pytest.approx(180.0)


def test_moving_a_light_changes_the_light_readings():
    sim = open_floor_crowbot()
    sim.step(0.1)
    before = list(sim.read("Light").data)
    lamp = sim.lights[0]
    sim.move_light(lamp.name, sim.state.pose.x + 0.3, sim.state.pose.y)
    sim.step(0.1)
    after = list(sim.read("Light").data)
    assert all(a < b - 300 for a, b in zip(after, before, strict=True))


def test_bounds_events_and_time_out_of_bounds():
    sim = Simulation("crowbot", "line_track", seed=0, spawn=Pose2D(0.05, 0.05, math.pi))
    sim.apply("Control", twist(0.12))
    sim.step(2.0)
    assert sim.state.time_out_of_bounds_s > 1.0
    assert EventKind.LEFT_BOUNDS in [e.kind for e in sim.drain_events()]


# ------------------------------------------------------------------------------- bad input
def test_unknown_robot_and_world_list_the_valid_ids():
    with pytest.raises(
        UnknownRobotError, match="crop_rover, crowbot, ir_scout, turtlebot, turtlebot3"
    ):
        Simulation("crowbotz", "wall_approach")
    with pytest.raises(WorldError, match="wall_approach"):
        Simulation("crowbot", "moon_base")


def test_robot_in_a_world_not_meant_for_it_is_refused_with_the_worlds_that_are():
    with pytest.raises(SimulationError, match="crop_rows"):
        Simulation("crop_rover", "line_track")


def test_wrong_message_type_names_topic_and_expected_type():
    sim = open_floor_crowbot()
    with pytest.raises(
        SimulationError, match=r"'Control' expects geometry_msgs/Twist, got std_msgs/Int32"
    ):
        sim.apply("Control", Int32(data=3))


def test_unknown_topic_and_publishing_to_a_sensor_topic_say_what_exists():
    sim = open_floor_crowbot()
    with pytest.raises(SimulationError, match=r"Distance .*Control"):
        sim.apply("cmd_vel", twist(0.1))
    with pytest.raises(SimulationError, match="commands go to Control, Leds, Buzzer"):
        sim.apply("Distance", Int32(data=3))


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_non_finite_commands_are_rejected_not_integrated(bad):
    sim = open_floor_crowbot()
    with pytest.raises(SimulationError, match=r"Control\.angular\.z is"):
        sim.apply("Control", twist(0.1, bad))
    sim.step(0.5)
    assert math.isfinite(sim.state.pose.x) and sim.state.distance_travelled_m == 0.0


@pytest.mark.parametrize(
    ("robot", "world", "topic", "message", "match"),
    [
        ("crowbot", "light_arena", "Leds", Int32MultiArray(data=[1, 2]), r"\[r, g, b\]"),
        ("crowbot", "light_arena", "Leds", Int32MultiArray(data=[0, 300, 0]), "0-255"),
        ("ir_scout", "obstacle_maze", "servo_angle", Int16(data=200), "between 0 and 180"),
        ("ir_scout", "obstacle_maze", "motor_command", String(data="fly"), "'forward'"),
        ("crop_rover", "crop_rows", "u", Float32(data=250.0), "between -100 and 100"),
    ],
)
def test_command_content_errors_are_sentences(robot, world, topic, message, match):
    sim = Simulation(robot, world)
    with pytest.raises(ValueError, match=match):
        sim.apply(topic, message)


def test_bad_step_seed_and_spawn_arguments():
    sim = open_floor_crowbot()
    for dt in (-0.1, math.nan, "1"):
        with pytest.raises(SimulationError, match="non-negative dt"):
            sim.step(dt)
    with pytest.raises(SimulationError, match="non-negative integer"):
        sim.reset(seed=-1)
    with pytest.raises(SimulationError, match="no spawn 'garage'"):
        Simulation("crowbot", "light_arena", spawn="garage")


def test_registry_entries_are_valid():
    assert registry_problems() == []
    assert robot_ids() == ("crop_rover", "crowbot", "ir_scout", "turtlebot", "turtlebot3")


def test_scene_carries_what_the_view_draws():
    sim = Simulation("crop_rover", "crop_rows", seed=0)
    sim.step(0.3)
    scene = sim.scene()
    assert scene.robot_id == "crop_rover" and scene.world_id == "crop_rows"
    assert set(scene.latest) >= {"scan", "psi", "imu", "odom"}
    assert np.isfinite([scene.pose.x, scene.pose.y, scene.pose.yaw]).all()


def test_scene_rays_end_where_the_sensor_measured():
    sim = Simulation("crowbot", "wall_approach", seed=0)
    sim.step(0.1)
    rays = sim.scene().rays["Distance"]
    assert rays.shape == (3, 4)  # cone edge, axis, cone edge
    axis_end_x = rays[1, 2]
    assert axis_end_x == pytest.approx(1.4, abs=0.015)  # the board's face
    ir = Simulation("ir_scout", "wall_approach", seed=0)
    ir.step(0.1)
    assert ir.scene().rays["ir_range"].shape == (1, 4)


def test_the_odometry_origin_stays_where_the_robot_started():
    # map -> odom on /tf is drawn from it: were it to move with the robot, every tf lookup of
    # odom -> base_link would read zero.
    sim = Simulation("turtlebot", "office", seed=0, spawn="corridor")
    start = sim.odometry_origin
    for _ in range(20):
        sim.apply("cmd_vel", twist(0.2))
        sim.step(0.1)
    assert sim.state.pose.x > start.x + 0.2
    assert (sim.odometry_origin.x, sim.odometry_origin.y) == pytest.approx((0.7, 3.1))


def test_velocity_topics_are_the_twist_commands_and_stop_zeroes_them():
    assert {r: get_robot(r).velocity_topics() for r in robot_ids()} == {
        "crop_rover": ("cmd_vel",),
        "crowbot": ("Control",),
        "ir_scout": ("cmd_vel",),
        "turtlebot": ("cmd_vel",),
        "turtlebot3": ("cmd_vel",),
    }
    sim = Simulation("crowbot", "wall_approach")
    sim.apply("Control", Twist(linear=Vector3(x=0.1)))
    sim.stop()
    assert sim.read("Control").linear.x == 0.0
