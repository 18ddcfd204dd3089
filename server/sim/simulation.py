"""The simulation a run engine drives: one robot in one world, advanced in fixed physics ticks.

Contract (checked, with sentences that say what to do):
    sim = Simulation("crowbot", "wall_approach", seed=0)
    sim.apply("Control", Twist(...))       # a command topic the robot subscribes to
    published = sim.step(0.05)             # sensor messages that fell due, in time order
    sim.read("Distance")                   # latest message on a topic (None before the first)
    sim.scene()                            # what to draw

The ticks between two events (a command, a sensor sample, the end of a step) are evaluated
together where nothing but motion happens (server/sim/tick_runs.py): the same ticks, within float
rounding; contacts and bounds crossings are taken one tick at a time (`tick_runs=False`: all).

Pure: no I/O, no wall clock. Time is kept in integer nanoseconds of simulated time, so tick and
sensor schedules never drift with float rounding; each sensor topic publishes at `phase +
k / rate` on the first tick at or after that instant. Randomness comes from one seed, split into
an independent stream per topic (numpy SeedSequence keyed by the topic name), so reading one
topic more or less often never changes another's noise: same seed, same commands -> identical
message streams, bit for bit.
"""

from __future__ import annotations

import math
import zlib
from collections.abc import Callable

import numpy as np

from sandbox.units import NS_PER_S
from server.sim.kinematics import body_velocities, integrate_arc, wrap_angle
from server.sim.obstacles import Obstacles
from server.sim.records import EventKind, Published, Scene, SimEvent
from server.sim.registry import get_robot, robots_for_world
from server.sim.robots.base import Direction, TopicSpec
from server.sim.sensors.base import SenseContext, Sensor
from server.sim.state import Pose2D, RobotState
from server.sim.tick_runs import (
    MIN_TICKS_FOR_A_RUN,
    ArrayRun,
    RunPoint,
    RunStart,
    SteadyRun,
    move_along,
    plan_run,
)
from server.sim.world import LightSource, World, WorldError, load_world

DEFAULT_PHYSICS_HZ = 1000.0  # [Hz] fine enough that a 0.13 m/s robot moves 0.13 mm per tick
# Odometry miscalibration: each wheel's effective radius differs from the nominal one by a
# seeded draw of this relative standard deviation, so dead reckoning drifts like a real base.
ODOMETRY_RADIUS_ERROR = 0.01  # [1]
_COLLISION_ITERATIONS = 4  # push-out passes per tick; a corner needs one per wall
# [s] a touch that begins this soon after the last one ended continues it (`contact_count`
# counts it once), as a bumper switch is debounced. A body turning on the spot against a crate
# (its disc sits ahead of the wheels) leaves and touches the surface every 1-8 ms within one
# 1.4 s contact (measured in ir_scout_avoidance's reference run), which counted one contact as
# five; a robot that backs off and drives in again takes far longer than 0.1 s.
CONTACT_DEBOUNCE_S = 0.1


class SimulationError(ValueError):
    """A call the simulation cannot accept; the message says what to do instead."""


def _topic_rng(seed: int, topic: str) -> np.random.Generator:
    return np.random.default_rng(
        np.random.SeedSequence(seed, spawn_key=(zlib.crc32(topic.encode()),))
    )


def _check_finite(message: object, path: str) -> None:
    """Reject NaN/inf anywhere in a command: integrating one would poison the pose forever."""
    for name in getattr(message, "__slots__", ()):
        value = getattr(message, name)
        if isinstance(value, float):
            if not math.isfinite(value):
                raise SimulationError(f"{path}.{name} is {value}; commands must be finite numbers")
        elif isinstance(value, (list, tuple)):
            for index, item in enumerate(value):
                if isinstance(item, float) and not math.isfinite(item):
                    raise SimulationError(
                        f"{path}.{name}[{index}] is {item}; commands must be finite numbers"
                    )
        elif hasattr(value, "__slots__"):
            _check_finite(value, f"{path}.{name}")


class Simulation:
    """One robot in one world, a `RobotBackend` (server/sim/backend.py). See the module
    docstring for the contract."""

    def __init__(
        self,
        robot: str,
        world: str | World,
        *,
        seed: int = 0,
        spawn: str | Pose2D | None = None,
        physics_hz: float = DEFAULT_PHYSICS_HZ,
        tick_runs: bool = True,
    ) -> None:
        """`tick_runs`: evaluate the ticks between two events as arrays (server/sim/tick_runs.py:
        the same ticks, within float rounding); False steps every tick on its own, the
        reference the tests hold tick runs to."""
        self.robot = get_robot(robot)
        self.world = world if isinstance(world, World) else load_world(world)
        if self.robot.id not in self.world.robots:
            raise SimulationError(
                f"robot '{self.robot.id}' is not meant for world '{self.world.id}'; worlds for "
                f"it: {', '.join(robots_for_world(self.robot.id))}"
            )
        if not (math.isfinite(physics_hz) and 10.0 <= physics_hz <= 100_000.0):
            raise SimulationError(f"physics_hz must be between 10 and 100000, got {physics_hz}")
        self._tick_ns = round(NS_PER_S / physics_hz)
        self._tick_s = self._tick_ns / NS_PER_S
        self._tick_runs = bool(tick_runs)
        self.obstacles = Obstacles(self.world)
        self._topics = {spec.name: spec for spec in self.robot.topics()}
        self._spawn = spawn
        self.reset(seed)

    # ----------------------------------------------------------------------------- lifecycle
    def reset(self, seed: int | None = None) -> list[Published]:
        """Start over at the spawn pose with fresh noise from `seed` (the last seed if None).

        Returns the messages that publish at time 0."""
        if seed is not None:
            if not isinstance(seed, int) or seed < 0:
                raise SimulationError(f"seed must be a non-negative integer, got {seed!r}")
            self.seed = seed
        spawn = self._spawn_pose(self._spawn)
        self.state = RobotState(pose=spawn, odometry_pose=Pose2D(0.0, 0.0, 0.0))
        self._odom_origin = spawn  # frozen: the physics replaces the state's pose, never moves it
        self.lights = self.world.lights
        self.motors = self.robot.build_motors()
        self.motors.reset()
        self.sensors: dict[str, Sensor] = self.robot.build_sensors()
        self._rngs = {name: _topic_rng(self.seed, name) for name in self.sensors}
        physics_rng = _topic_rng(self.seed, "__physics__")
        self._wheel_radius_m = self.robot.geometry.wheel_radius_m
        self._track_m = self.robot.geometry.track_m
        # Effective/nominal radius of each wheel as dead reckoning wrongly assumes it.
        self._odom_left_scale, self._odom_right_scale = (
            1.0 + physics_rng.normal(0.0, ODOMETRY_RADIUS_ERROR, 2)
        ).tolist()
        self._period_ns = {n: round(NS_PER_S / s.rate_hz) for n, s in self.sensors.items()}
        self._next_due_ns = {n: round(s.phase_s * NS_PER_S) for n, s in self.sensors.items()}
        self._earliest_due_ns = min(self._next_due_ns.values())
        for sensor in self.sensors.values():
            sensor.reset()
        self._now_ns = 0
        self._target_ns = 0
        self._latest: dict[str, object] = {}
        self._events: list[SimEvent] = []
        self._clearance_m = 0.0
        self._contact_ended_s = -math.inf  # [s] when the last contact ended (the debounce)
        self._single_ticks = 0  # ticks to take one by one before planning a run again
        self._out_of_bounds = not self.world.in_bounds(spawn.x, spawn.y)
        return self._publish_due()

    def _spawn_pose(self, spawn: str | Pose2D | None) -> Pose2D:
        if isinstance(spawn, Pose2D):
            return spawn
        try:
            chosen = self.world.spawn(spawn or None)
        except WorldError as error:
            raise SimulationError(str(error)) from None
        return Pose2D(chosen.x, chosen.y, chosen.yaw)

    # ----------------------------------------------------------------------------- topics
    @property
    def odometry_origin(self) -> Pose2D:
        """Where the odometry frame starts: the world pose the robot was reset to."""
        return self._odom_origin

    @property
    def time_s(self) -> float:
        return self._now_ns / NS_PER_S

    @property
    def tick_s(self) -> float:
        """[s] one physics tick: the smallest step that moves the simulation on."""
        return self._tick_s

    @property
    def topics(self) -> tuple[TopicSpec, ...]:
        return tuple(self._topics.values())

    def _topic(self, topic: str) -> TopicSpec:
        spec = self._topics.get(topic)
        if spec is None:
            raise SimulationError(
                f"robot '{self.robot.id}' has no topic '{topic}'; its topics are "
                + ", ".join(f"{t.name} ({t.type_name}, {t.direction})" for t in self.topics)
            )
        return spec

    def apply(self, topic: str, message: object) -> None:
        """Deliver a command message; it acts from the next physics tick on."""
        spec = self._topic(topic)
        if spec.direction is not Direction.SUBSCRIBE:
            raise SimulationError(
                f"'{topic}' is a sensor topic the robot publishes; commands go to "
                + ", ".join(t.name for t in self.topics if t.direction is Direction.SUBSCRIBE)
            )
        if not isinstance(message, spec.msg_type):
            got = getattr(message, "_type", type(message).__name__)
            raise SimulationError(f"topic '{topic}' expects {spec.type_name}, got {got}")
        _check_finite(message, topic)
        self.robot.apply_command(topic, message, self.state, self.motors, self.time_s)
        self._latest[topic] = message

    def read(self, topic: str) -> object | None:
        """The latest message on `topic` (a sensor reading or the last command); None before
        the topic first published or was commanded."""
        self._topic(topic)
        return self._latest.get(topic)

    # ----------------------------------------------------------------------------- actions
    def press_button(self, pressed: bool) -> None:
        self.state.button_pressed = bool(pressed)

    def move_light(self, name: str, x: float, y: float) -> None:
        """Move a movable light source to (x, y) [m]."""
        names = [light.name for light in self.lights]
        if name not in names:
            raise SimulationError(f"world '{self.world.id}' has no light '{name}'; lights: {names}")
        if not (math.isfinite(x) and math.isfinite(y)):
            raise SimulationError(f"light position must be finite, got ({x}, {y})")
        if not self.world.in_bounds(x, y):
            min_x, min_y, max_x, max_y = self.world.bounds
            raise SimulationError(
                f"({x:.2f}, {y:.2f}) is outside the world ({min_x}..{max_x}, {min_y}..{max_y} m)"
            )
        lights = list(self.lights)
        index = names.index(name)
        if not lights[index].movable:
            raise SimulationError(f"light '{name}' is fixed in world '{self.world.id}'")
        old = lights[index]
        lights[index] = LightSource(old.name, float(x), float(y), old.z, old.intensity, True)
        self.lights = tuple(lights)

    def stop(self) -> None:
        """Zero velocity on every velocity (Twist) topic, from the next tick on."""
        for name in self.robot.velocity_topics():
            self.apply(name, self._topics[name].msg_type())

    def take_logs(self) -> list[str]:
        """A simulated robot logs nothing of its own (a real one's firmware does)."""
        return []

    def next_publication_s(self) -> float:
        """Simulated time [s] at which the next sensor message falls due."""
        return self._earliest_due_ns / NS_PER_S

    def drain_events(self) -> list[SimEvent]:
        """Contact and bounds events since the last call."""
        events, self._events = self._events, []
        return events

    def note_readers(self, is_read: Callable[[str], bool]) -> None:
        """Which topics the run's nodes read: a simulated robot never goes silent, so unused."""

    # ----------------------------------------------------------------------------- time
    def step(self, dt_s: float) -> list[Published]:
        """Advance simulated time by `dt_s` [s] in whole physics ticks; return what published.

        Time not filling a whole tick carries over to the next call, so many small steps add
        up to exactly the same ticks as one big step."""
        if not (isinstance(dt_s, (int, float)) and math.isfinite(dt_s) and dt_s >= 0):
            raise SimulationError(
                f"step(dt) needs a finite, non-negative dt in seconds, got {dt_s!r}"
            )
        self._target_ns += round(dt_s * NS_PER_S)
        published: list[Published] = []
        tick_ns = self._tick_ns
        while self._now_ns + tick_ns <= self._target_ns:
            ticks = (self._target_ns - self._now_ns) // tick_ns
            run = self._plan_run(ticks)
            if run is None:
                self._tick()
                published.extend(self._publish_due())
            else:
                published.extend(self._follow(run))
        return published

    # ----------------------------------------------------------------------------- tick runs
    def _plan_run(self, ticks: int) -> ArrayRun | SteadyRun | None:
        """The next `ticks` ticks (or the first part of them) as one run where nothing but
        motion happens (server/sim/tick_runs.py); None: take the next tick on its own (in
        contact, out of bounds, clearance used up, a short stretch)."""
        state, motors = self.state, self.motors
        if self._single_ticks > 0:
            self._single_ticks -= 1
            return None
        if (
            not self._tick_runs
            or ticks < MIN_TICKS_FOR_A_RUN
            or state.in_contact
            or self._out_of_bounds
            or self._clearance_m <= 0.0
            or not hasattr(motors, "step_many")
            or not hasattr(motors, "__dataclass_fields__")  # no state to put back
        ):
            return None
        pose, odom = state.pose, state.odometry_pose
        start = RunStart(
            pose=(pose.x, pose.y, pose.yaw),
            odometry=(odom.x, odom.y, odom.yaw),
            clearance_m=self._clearance_m,
            bounds=self.world.bounds,
            wheel_radius_m=self._wheel_radius_m,
            track_m=self._track_m,
            odometry_scales=(self._odom_left_scale, self._odom_right_scale),
            body_offset_m=self.robot.geometry.body_offset_x_m,
            tick_s=self._tick_s,
        )
        run = plan_run(start, motors, ticks)
        if run.ticks < MIN_TICKS_FOR_A_RUN:
            # One by one up to where the clearance runs out or the bounds are crossed.
            self._single_ticks = run.ticks
            return None
        return run

    def _follow(self, run: ArrayRun | SteadyRun) -> list[Published]:
        """Move the state along `run`, stopping at each tick where a sensor falls due to let
        it sample the robot there."""
        published = []
        tick_ns = self._tick_ns
        done, before = 0, run.point(0)
        while done < run.ticks:
            end = run.ticks
            if self._earliest_due_ns > self._now_ns:
                end = min(end, done - ((self._now_ns - self._earliest_due_ns) // tick_ns))
            after = run.point(end)
            self._commit(before, after, end - done)
            published.extend(self._publish_due())
            done, before = end, after
        return published

    def _commit(self, before: RunPoint, after: RunPoint, ticks: int) -> None:
        """The state `ticks` ticks further along a run, from point `before` to `after`."""
        move_along(self.state, before, after, self._wheel_radius_m, self._track_m)
        self._clearance_m -= after.body_m - before.body_m
        self._now_ns += ticks * self._tick_ns
        # One call for the stretch: `advance` adds up over time (RobotModel.advance).
        self.robot.advance(self.state, ticks * self._tick_s, self._now_ns / NS_PER_S)

    def _tick(self) -> None:
        dt = self._tick_s
        state = self.state
        wheel_radius, track = self._wheel_radius_m, self._track_m
        left, right = self.motors.step(dt)
        linear, angular = body_velocities(left, right, wheel_radius, track)
        pose = state.pose
        x, y, yaw = integrate_arc(pose.x, pose.y, pose.yaw, linear, angular, dt)
        x, y = self._resolve_contacts(pose.x, pose.y, pose.yaw, x, y, yaw)
        state.distance_travelled_m += math.hypot(x - pose.x, y - pose.y)
        state.pose = Pose2D(x, y, yaw)
        state.linear_m_s, state.angular_rad_s = linear, angular
        state.wheel_left_rad_s, state.wheel_right_rad_s = left, right
        state.wheel_left_travel_rad += left * dt
        state.wheel_right_travel_rad += right * dt
        # Dead reckoning with the (miscalibrated) radii, wheels slipping against walls included.
        odom_v, odom_w = body_velocities(
            left * self._odom_left_scale, right * self._odom_right_scale, wheel_radius, track
        )
        odom = state.odometry_pose
        state.odometry_pose = Pose2D(*integrate_arc(odom.x, odom.y, odom.yaw, odom_v, odom_w, dt))
        self._now_ns += self._tick_ns
        self.robot.advance(state, dt, self._now_ns / NS_PER_S)
        if self._out_of_bounds or not self.world.in_bounds(x, y):
            self._track_bounds(x, y, dt)

    def _resolve_contacts(
        self, old_x: float, old_y: float, old_yaw: float, x: float, y: float, yaw: float
    ) -> tuple[float, float]:
        """Push the body out of anything it overlaps; count contacts as they begin. Takes and
        returns the pose (the point between the wheels); the body disc sits `body_offset_x_m`
        ahead of it, so turning on the spot sweeps an off-centre body as on the real robot.

        A distance query costs tens of microseconds, so it only runs when the body has used
        up its last known clearance (conservative advancement): exact, and free in open space."""
        geometry = self.robot.geometry
        radius, offset = geometry.body_radius_m, geometry.body_offset_x_m
        old_cx, old_cy = old_x + offset * math.cos(old_yaw), old_y + offset * math.sin(old_yaw)
        cx, cy = x + offset * math.cos(yaw), y + offset * math.sin(yaw)
        self._clearance_m -= math.hypot(cx - old_cx, cy - old_cy)
        if self._clearance_m > 0.0:
            if self.state.in_contact:
                self._set_contact(False, (), x, y)
            return x, y
        angles: np.ndarray = np.zeros(0)
        nearest: float | None = None  # [m] from the body's centre where it ends up
        for _ in range(_COLLISION_ITERATIONS):
            push, touching, nearest = self.obstacles.contacts(cx, cy, radius)
            if len(push) == 0:
                break
            if len(angles) == 0:
                angles = touching
            # Resolve the deepest overlap first; a corner's second wall is the next pass.
            # (Summing would push twice at a box corner, where two edges share the point.)
            deepest = int(np.argmax(np.hypot(push[:, 0], push[:, 1])))
            cx += float(push[deepest, 0])
            cy += float(push[deepest, 1])
            nearest = None  # measured before this push
        if nearest is None:
            nearest = self.obstacles.clearance(cx, cy)
        x, y = cx - offset * math.cos(yaw), cy - offset * math.sin(yaw)
        # Margin of 0.5 mm so a robot resting against a wall keeps reporting the contact.
        self._clearance_m = nearest - radius - 0.0005
        robot_frame = tuple(wrap_angle(float(a) - self.state.pose.yaw) for a in angles)
        self._set_contact(len(angles) > 0, robot_frame, x, y)
        return x, y

    def _set_contact(self, touching: bool, angles: tuple[float, ...], x: float, y: float) -> None:
        state = self.state
        if touching and not state.in_contact:
            if self.time_s - self._contact_ended_s >= CONTACT_DEBOUNCE_S:
                state.contact_count += 1  # else the last contact goes on (CONTACT_DEBOUNCE_S)
            self._events.append(SimEvent(EventKind.CONTACT_BEGAN, self.time_s, x, y))
        elif not touching and state.in_contact:
            self._contact_ended_s = self.time_s
            self._events.append(SimEvent(EventKind.CONTACT_ENDED, self.time_s, x, y))
        state.in_contact = touching
        state.contact_angles_rad = angles

    def _track_bounds(self, x: float, y: float, dt: float) -> None:
        outside = not self.world.in_bounds(x, y)
        if outside:
            self.state.time_out_of_bounds_s += dt
        if outside != self._out_of_bounds:
            kind = EventKind.LEFT_BOUNDS if outside else EventKind.ENTERED_BOUNDS
            self._events.append(SimEvent(kind, self.time_s, x, y))
            self._out_of_bounds = outside

    def _publish_due(self) -> list[Published]:
        now = self._now_ns
        if now < self._earliest_due_ns:
            return []
        due = [name for name, when in self._next_due_ns.items() if when <= now]
        ctx = SenseContext(self.world, self.obstacles, self.state, self.time_s, self.lights)
        published = []
        for name in due:
            message = self.sensors[name].sample(ctx, self._rngs[name])
            self._latest[name] = message
            published.append(Published(name, self.time_s, message))
            period = self._period_ns[name]
            # Skip slots a coarse tick jumped over instead of publishing a burst of duplicates.
            behind = (now - self._next_due_ns[name]) // period + 1
            self._next_due_ns[name] += behind * period
        self._earliest_due_ns = min(self._next_due_ns.values())
        return published

    # ----------------------------------------------------------------------------- drawing
    def scene(self) -> Scene:
        state = self.state
        return Scene(
            time_s=self.time_s,
            robot_id=self.robot.id,
            world_id=self.world.id,
            pose=state.pose,  # frozen, so the scene keeps this instant's pose
            leds_rgb=state.leds_rgb,
            buzzer_on=state.buzzer_on,
            servo_angle_deg=state.servo_angle_deg,
            in_contact=state.in_contact,
            lights=self.lights,
            latest=dict(self._latest),
            rays=self._rays(),
        )

    def _rays(self) -> dict[str, np.ndarray]:
        ctx = SenseContext(self.world, self.obstacles, self.state, self.time_s, self.lights)
        rays = {}
        for name, sensor in self.sensors.items():
            message = self._latest.get(name)
            if message is not None and hasattr(sensor, "rays"):
                rays[name] = sensor.rays(ctx, message)
        return rays
