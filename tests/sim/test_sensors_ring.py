"""UltrasonicRing: rangers fired one after another, cone echoes, grazing surfaces, seeding."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sandbox.msgs.sensor_msgs import Range
from server.sim.sensors.ultrasonic_ring import RingRanger, UltrasonicRing
from server.sim.state import Pose2D, RobotState
from server.sim.world import World
from tests.sim.shapes import make_context, make_world


def front_ranger(ring: UltrasonicRing | None = None) -> RingRanger:
    ring = ring if ring is not None else UltrasonicRing()
    (ranger,) = [r for r in ring.rangers if r.bearing_rad == 0.0]
    return ranger


def reading(ranger: RingRanger, world: World, seed: int = 0, pose: Pose2D | None = None) -> float:
    state = RobotState(pose=pose if pose is not None else Pose2D())
    message = ranger.sample(make_context(world, state), np.random.default_rng(seed))
    return float(message.range)


def test_ring_has_seven_rangers_on_seven_topics() -> None:
    ring = UltrasonicRing()
    assert len(ring.rangers) == 7
    assert list(ring.topics) == [f"ultrasonic/range_{i}" for i in range(7)]
    assert [math.degrees(r.bearing_rad) for r in ring.rangers] == pytest.approx(
        [-90, -60, -30, 0, 30, 60, 90]
    )
    assert len({r.frame_id for r in ring.rangers}) == 7


def test_rangers_fire_one_after_another_in_the_documented_sequence() -> None:
    ring = UltrasonicRing()
    phases = [r.phase_s for r in ring.rangers]
    assert len(set(phases)) == 7  # never two at once
    assert [r.rate_hz for r in ring.rangers] == pytest.approx([1.0 / ring.cycle_s] * 7)
    assert ring.cycle_s == pytest.approx(7 * 0.06)
    assert all(0.0 <= p < ring.cycle_s for p in phases)  # all within one cycle
    firing_order = sorted(range(7), key=lambda index: phases[index])
    assert tuple(firing_order) == ring.activation_sequence == (0, 3, 6, 2, 5, 1, 4)
    gaps = np.diff(sorted(phases))
    assert np.all(gaps >= 0.06 - 1e-12)  # the HC-SR04's echo has died out
    for first, second in zip(firing_order, firing_order[1:] + firing_order[:1], strict=True):
        assert abs(first - second) > 1, (first, second)  # no neighbours back to back


@pytest.mark.parametrize(
    "sequence",
    [(0, 1, 3, 5, 2, 4, 6), (0, 3, 6, 2, 5, 1), (0, 3, 6, 2, 5, 1, 1), (0, 3, 6, 2, 5, 4, 1)],
)
def test_sequences_that_fire_neighbours_or_skip_rangers_are_refused(
    sequence: tuple[int, ...],
) -> None:
    with pytest.raises(ValueError, match="activation_sequence"):
        UltrasonicRing(activation_sequence=sequence)


def test_wall_at_one_metre_reads_one_metre() -> None:
    ranger = front_ranger()
    # The ranger sits 0.15 m ahead of the body centre; the wall is 1.0 m ahead of the ranger.
    wall = (1.15, -3.0, 1.15, 3.0)
    values = [reading(ranger, make_world(segments=[wall]), seed) for seed in range(20)]
    assert np.mean(values) == pytest.approx(1.0, abs=0.01)
    assert 0.0 < np.std(values) < 0.02


def test_side_ranger_follows_the_robot_heading() -> None:
    ring = UltrasonicRing()
    left = ring.rangers[6]  # +90 degrees
    pose = Pose2D(x=0.5, y=0.5, yaw=math.pi)  # facing -x: its left is -y
    wall_y = 0.5 - 0.15 - 0.7  # ranger 0.15 m off centre, wall 0.7 m beyond
    wall = (-3.0, wall_y, 3.0, wall_y)
    assert reading(left, make_world(segments=[wall]), pose=pose) == pytest.approx(0.7, abs=0.02)


def test_a_wall_at_grazing_incidence_gives_no_echo() -> None:
    ranger = front_ranger()
    # A wall running along the beam, 0.3 m to the side: the upper edge of the cone meets it at
    # ~82 degrees from its normal, so the ping glances off and never comes back.
    grazing_wall = (0.0, 0.3, 6.0, 0.3)
    world = make_world(segments=[grazing_wall])
    assert reading(ranger, world) == ranger.max_range_m
    # Not vacuous: a ranger that accepted any incidence would see the wall.
    accepting = RingRanger(
        bearing_rad=0.0, rate_hz=1.0, phase_s=0.0, frame_id="t", max_incidence_rad=math.pi / 2
    )
    assert reading(accepting, world) < 3.0


def test_a_round_post_echoes_from_its_facing_side() -> None:
    post = (1.15, 0.0, 0.05)
    assert reading(front_ranger(), make_world(circles=[post])) == pytest.approx(0.95, abs=0.02)


def test_cone_sees_an_object_off_the_axis() -> None:
    ranger = front_ranger()
    inside = math.radians(6.0)  # within the 7.5-degree half-cone
    post = (0.15 + 1.5 * math.cos(inside), 1.5 * math.sin(inside), 0.05)
    assert reading(ranger, make_world(circles=[post])) == pytest.approx(1.45, abs=0.03)
    outside = math.radians(12.0)
    post = (0.15 + 1.5 * math.cos(outside), 1.5 * math.sin(outside), 0.05)
    assert reading(ranger, make_world(circles=[post])) == ranger.max_range_m


def test_nothing_in_range_reads_max_range_and_message_fields() -> None:
    ranger = front_ranger()
    message = ranger.sample(make_context(make_world()), np.random.default_rng(0))
    assert isinstance(message, Range)
    assert message.range == pytest.approx(4.0)
    assert message.radiation_type == Range.ULTRASOUND
    assert message.field_of_view == pytest.approx(math.radians(15.0))
    assert (message.min_range, message.max_range) == (pytest.approx(0.02), pytest.approx(4.0))
    wire = message.serialize()
    assert Range.deserialize(wire).serialize() == wire


def test_readings_are_seeded() -> None:
    world = make_world(segments=[(2.0, -3.0, 2.0, 3.0)])
    ranger = front_ranger()
    assert reading(ranger, world, seed=4) == reading(ranger, world, seed=4)
    assert reading(ranger, world, seed=4) != reading(ranger, world, seed=5)
