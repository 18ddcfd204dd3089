"""The guide's figures, made from the real thing and committed under docs/images/:

    python3 -m guide.figures                     # all of them (~2 min on the 2-core machine)
    python3 -m guide.figures robots exercises    # only the matplotlib figures
    python3 -m guide.figures pages               # only the screenshots (Chromium)

- `robots/<id>.png`: each robot from above at its start in one of its worlds, with the rays its
  range sensors cast at that moment (a real `Simulation`, its scene's rays).
- `exercises/<id>.png`: a real lockstep run of each exercise's reference solution in the
  sandbox, on its first seed, read back from its MCAP recording: the true path in the world and
  the exercise's key signals.
- `pages/*.png`: the lab's pages in Debian's Chromium through Playwright, on a server started as
  the end-to-end tests start it (`guide/screens.py`).

Then `python3 -m guide.build` puts them into the site.
"""

from __future__ import annotations

import argparse
import math
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from server.sim.world import World, load_world

IMAGES = Path(__file__).resolve().parents[1] / "docs" / "images"
DPI = 110
ROBOT_WORLDS = {  # a world each robot starts in with something in its sensors' view
    "crowbot": "light_arena",
    "crop_rover": "crop_rows",
    "ir_scout": "obstacle_maze",
    "turtlebot": "office",
    "turtlebot3": "office",
}
SENSOR_SETTLE_S = 1.0  # [s] every sensor (the slowest, 2.4 Hz) has published once by then
DENSE_RAYS = 40  # more rays than this are a scan, drawn faintly with its hit points
ROBOT_VIEW_M = 1.3  # [m] half the side of the square drawn around the robot


def _save(figure, path: Path) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    # No timestamp or software version in the PNG: a figure redrawn from the same run is the
    # same file.
    figure.savefig(path, dpi=DPI, metadata={"Software": None}, bbox_inches="tight")
    plt.close(figure)
    print(f"  {path.relative_to(IMAGES.parent.parent)}")


def draw_world(axes, world: World) -> None:
    """Walls and box edges, posts and plants, floor tape, lights: the world from above."""
    for x0, y0, x1, y1 in world.tape_segments:
        axes.plot([x0, x1], [y0, y1], color="0.55", linewidth=3, solid_capstyle="butt")
    for x0, y0, x1, y1 in world.segments:
        axes.plot([x0, x1], [y0, y1], color="0.15", linewidth=1.6)
    for x, y, radius in world.circles:
        axes.add_patch(plt.Circle((x, y), radius, color="#3f7f3f", alpha=0.8))
    for light in world.lights:
        axes.plot(light.x, light.y, marker="*", color="#e0a000", markersize=14)
    axes.set_aspect("equal")
    axes.set_xlabel("x [m]")
    axes.set_ylabel("y [m]")


def draw_robot(axes, robot, x: float, y: float, yaw: float) -> None:
    geometry = robot.geometry
    axes.add_patch(plt.Circle((x, y), geometry.body_radius_m, fill=False, color="#1d4ed8", lw=2))
    for side in (1, -1):  # the two wheels, drawn as short bars across the track
        wx = x - side * math.sin(yaw) * geometry.track_m / 2
        wy = y + side * math.cos(yaw) * geometry.track_m / 2
        dx, dy = math.cos(yaw) * geometry.wheel_radius_m, math.sin(yaw) * geometry.wheel_radius_m
        axes.plot([wx - dx, wx + dx], [wy - dy, wy + dy], color="#1d4ed8", linewidth=5)
    reach = geometry.body_radius_m * 1.4
    axes.annotate("", (x + reach * math.cos(yaw), y + reach * math.sin(yaw)), (x, y),
                  arrowprops={"arrowstyle": "->", "color": "#1d4ed8", "lw": 2})  # fmt: skip


def _frame_pose(robot, state, frame_id: str) -> tuple[float, float, float, float] | None:
    """A sensor frame in the robot frame: (x, y, yaw, roll); roll pi = angles grow clockwise."""
    frames = robot.sensor_frames(state)
    if frame_id in ("base_link", "base_footprint", ""):
        return (0.0, 0.0, 0.0, 0.0)
    mount = frames.get(frame_id)
    if mount is None:
        return None
    return (*mount[:3], mount[3] if len(mount) > 3 else 0.0)


def message_rays(robot, state, pose, message) -> list[tuple[float, float, float, float]]:
    """World segments for what a LaserScan or Range measured, placed by its header's frame."""
    header = getattr(message, "header", None)
    if header is None or (not hasattr(message, "range") and not hasattr(message, "ranges")):
        return []
    frame = _frame_pose(robot, state, header.frame_id)
    if frame is None:
        return []
    fx, fy, fyaw, roll = frame
    ox = pose.x + fx * math.cos(pose.yaw) - fy * math.sin(pose.yaw)
    oy = pose.y + fx * math.sin(pose.yaw) + fy * math.cos(pose.yaw)
    sign = -1.0 if abs(roll - math.pi) < 1e-6 else 1.0
    if hasattr(message, "ranges"):  # LaserScan: a ray to each valid return
        pairs = [(message.angle_min + i * message.angle_increment, r)
                 for i, r in enumerate(message.ranges)]  # fmt: skip
        lo, hi = message.range_min, message.range_max
    else:  # Range: its cone's axis and edges
        half = message.field_of_view / 2
        pairs = [(a, message.range) for a in (-half, 0.0, half)]
        lo, hi = message.min_range, message.max_range
    rays = []
    for angle, length in pairs:
        if not (math.isfinite(length) and lo <= length <= hi):
            continue
        heading = pose.yaw + fyaw + sign * angle
        rays.append((ox, oy, ox + length * math.cos(heading), oy + length * math.sin(heading)))
    return rays


def robot_figure(robot_id: str) -> None:
    from server.sim import Simulation

    world_id = ROBOT_WORLDS[robot_id]
    simulation = Simulation(robot_id, world_id, seed=1)
    simulation.step(SENSOR_SETTLE_S)
    scene = simulation.scene()
    pose = scene.pose
    figure, axes = plt.subplots(figsize=(6.4, 5.6))
    draw_world(axes, simulation.world)
    colours = plt.get_cmap("tab10")
    drawn = {topic: np.asarray(rays) for topic, rays in scene.rays.items()}
    for topic, message in scene.latest.items():
        rays = message_rays(simulation.robot, simulation.state, pose, message)
        if rays and topic not in drawn:
            drawn[topic] = np.asarray(rays)
    for index, (topic, rays) in enumerate(sorted(drawn.items())):
        colour = colours(index % 10)
        dense = len(rays) > DENSE_RAYS  # a scan: faint rays, its hit points marked
        for x0, y0, x1, y1 in rays:
            axes.plot([x0, x1], [y0, y1], color=colour, linewidth=0.6 if dense else 0.9,
                      alpha=0.15 if dense else 0.85)  # fmt: skip
        axes.plot(rays[:, 2], rays[:, 3], linestyle="none", marker=".",
                  markersize=3 if dense else 5, color=colour, label=topic)  # fmt: skip
    draw_robot(axes, simulation.robot, pose.x, pose.y, pose.yaw)
    axes.set_xlim(pose.x - ROBOT_VIEW_M, pose.x + ROBOT_VIEW_M)
    axes.set_ylim(pose.y - ROBOT_VIEW_M, pose.y + ROBOT_VIEW_M)
    axes.set_title(f"{robot_id} in {world_id}: what its sensors measured at t = "
                   f"{SENSOR_SETTLE_S:g} s", fontsize=10)  # fmt: skip
    if drawn:
        axes.legend(loc="upper right", fontsize=8, title="rays of", title_fontsize=8)
    _save(figure, IMAGES / "robots" / f"{robot_id}.png")


# ------------------------------------------------------------------------------ exercises
Signal = tuple[str, Callable[[object], float], str]  # topic, value of a message, label


def _field(*path: str | int) -> Callable[[object], float]:
    def get(message: object) -> float:
        value = message
        for part in path:
            value = value[part] if isinstance(part, int) else getattr(value, part)
        return float(value)

    return get


SIGNALS: dict[str, list[Signal]] = {
    "crowbot_distance_pid": [
        ("Distance", lambda m: m.data / 100.0, "Distance [m]"),
        ("Control", _field("linear", "x"), "Control linear.x [m/s]"),
    ],
    "crowbot_light_tracking": [
        ("Light", _field("data", 0), "Light right (raw)"),
        ("Light", _field("data", 1), "Light left (raw)"),
        ("Control", _field("angular", "z"), "Control angular.z [rad/s]"),
    ],
    "crowbot_data_logger": [
        ("Button", lambda m: float(m.data), "Button"),
        ("Distance", _field("data"), "Distance [cm]"),
        ("Light", _field("data", 0), "Light right (raw)"),
        ("Line", _field("data", 0), "Line right (raw)"),
    ],
    "crop_row_fuzzy": [
        ("u", _field("data"), "u (control word)"),
        ("psi", _field("data"), "psi [rad]"),
    ],
    "ir_scout_avoidance": [
        ("ir_range", _field("range"), "ir_range [m]"),
        ("servo_position", _field("data"), "servo_position [deg]"),
    ],
    "turtlebot_stanley": [
        ("cmd_vel", _field("linear", "x"), "cmd_vel linear.x [m/s]"),
        ("cmd_vel", _field("angular", "z"), "cmd_vel angular.z [rad/s]"),
    ],
}
SIGNALS["turtlebot_stanley_ros2"] = SIGNALS["turtlebot_stanley"]


def reference_run(exercise_id: str, out_dir: Path):
    """The reference solution's run on the exercise's first seed (and first start pose)."""
    from sandbox.launcher import Launcher
    from server.exercises.evidence import load_evidence
    from server.exercises.grading import reference_nodes, run_spec
    from server.exercises.registry import get_exercise
    from server.runs.run import Run

    exercise = get_exercise(exercise_id)
    start = exercise.starts[0] if exercise.starts else None
    launcher = Launcher(pool_size=0)
    try:
        spec = run_spec(exercise, reference_nodes(exercise), exercise.seeds[0], start)
        result = Run(spec, launcher, out_dir).execute()
    finally:
        launcher.close()
    return exercise, result, load_evidence(result, out_dir)


def exercise_figure(exercise_id: str) -> None:
    with tempfile.TemporaryDirectory(prefix=f"guide-{exercise_id}-") as folder:
        exercise, result, evidence = reference_run(exercise_id, Path(folder) / "run")
    signals = SIGNALS[exercise_id]
    figure = plt.figure(figsize=(11, 4.6))
    grid = figure.add_gridspec(len(signals), 2, width_ratios=(1.05, 1.0))
    world_axes = figure.add_subplot(grid[:, 0])
    draw_world(world_axes, load_world(exercise.world))
    for _, plan in evidence.series("plan")[:: max(1, len(evidence.series("plan")) // 12)]:
        xs = [pose.pose.position.x for pose in plan.poses]
        ys = [pose.pose.position.y for pose in plan.poses]
        world_axes.plot(xs, ys, color="#e07000", linewidth=1, alpha=0.6)
    world_axes.plot(evidence.pose_x, evidence.pose_y, color="#1d4ed8", linewidth=1.5)
    if len(evidence.pose_x):
        draw_robot(world_axes, get_robot_model(exercise.robot), evidence.pose_x[0],
                   evidence.pose_y[0], evidence.pose_yaw[0])  # fmt: skip
    world_axes.set_title(f"{exercise.world}: the path driven (blue)"
                         + (", planned paths (orange)" if evidence.series("plan") else ""),
                         fontsize=9)  # fmt: skip
    axes = None
    for row, (topic, value, label) in enumerate(signals):
        axes = figure.add_subplot(grid[row, 1], sharex=axes)
        samples = evidence.series(topic)
        times = [t for t, _ in samples]
        axes.plot(times, [value(message) for _, message in samples], linewidth=1)
        axes.set_ylabel(label, fontsize=8)
        axes.tick_params(labelsize=8)
        axes.grid(alpha=0.3)
    if axes is not None:
        axes.set_xlabel("time [s]")
    figure.suptitle(f"{exercise.title}: reference solution, seed {exercise.seeds[0]} "
                    f"({result.reason})", fontsize=10)  # fmt: skip
    _save(figure, IMAGES / "exercises" / f"{exercise_id}.png")


def get_robot_model(robot_id: str):
    from server.sim.registry import get_robot

    return get_robot(robot_id)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python3 -m guide.figures",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("parts", nargs="*", choices=["robots", "exercises", "pages"],
                        default=["robots", "exercises", "pages"])  # fmt: skip
    parser.add_argument("--only", default=None, help="one robot or exercise id")
    args = parser.parse_args(argv)
    if "robots" in args.parts:
        print("robots:")
        for robot_id in ROBOT_WORLDS:
            if args.only in (None, robot_id):
                robot_figure(robot_id)
    if "exercises" in args.parts:
        print("exercises:")
        for exercise_id in SIGNALS:
            if args.only in (None, exercise_id):
                exercise_figure(exercise_id)
    if "pages" in args.parts:
        from guide import screens

        print("pages:")
        screens.take(IMAGES / "pages")
    return 0


if __name__ == "__main__":
    sys.exit(main())
