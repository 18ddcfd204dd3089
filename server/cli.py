"""`robodojo`: the command line.

Until the run engine and the web server land, `robodojo run` drives the simulator with a constant
velocity command and prints what the robot publishes, like `rostopic echo`:

    robodojo run --robot crowbot --world wall_approach --linear 0.1 --duration 3 --echo Distance
"""

from __future__ import annotations

import argparse
import sys

from sandbox.msgs.geometry_msgs import Twist, Vector3
from server.sim import Simulation, get_robot, load_world, robot_ids, robots_for_world, world_ids
from server.sim.robots.base import Direction


def _cmd_robots(_: argparse.Namespace) -> int:
    for robot_id in robot_ids():
        robot = get_robot(robot_id)
        print(f"{robot_id}: {robot.title}")
        print(f"  source: {robot.source}")
        print(f"  worlds: {', '.join(robots_for_world(robot_id))}")
        for topic in robot.topics():
            rate = f" @ {topic.rate_hz:g} Hz" if topic.rate_hz else ""
            print(
                f"  {topic.direction:9} {topic.name} [{topic.type_name}]{rate}: {topic.description}"
            )
    return 0


def _cmd_worlds(_: argparse.Namespace) -> int:
    for world_id in world_ids():
        world = load_world(world_id)
        print(f"{world_id}: {world.title} (robots: {', '.join(world.robots)})")
    return 0


def _velocity_topic(robot_id: str) -> str:
    for topic in get_robot(robot_id).topics():
        if topic.direction is Direction.SUBSCRIBE and topic.msg_type is Twist:
            return topic.name
    raise SystemExit(f"robot '{robot_id}' takes no velocity command")


def _cmd_run(args: argparse.Namespace) -> int:
    sim = Simulation(args.robot, args.world, seed=args.seed, spawn=args.spawn)
    sim.apply(
        _velocity_topic(args.robot),
        Twist(linear=Vector3(x=args.linear), angular=Vector3(z=args.angular)),
    )
    counts: dict[str, int] = {}
    steps = max(1, round(args.duration / 0.05))
    for _ in range(steps):
        for item in sim.step(0.05):
            counts[item.topic] = counts.get(item.topic, 0) + 1
            if item.topic in args.echo:
                print(f"[{item.time_s:8.3f}] {item.topic}: {item.message}")
    pose = sim.state.pose
    print(
        f"t={sim.time_s:.3f} s  pose=({pose.x:.3f} m, {pose.y:.3f} m, {pose.yaw:.3f} rad)  "
        f"travelled={sim.state.distance_travelled_m:.3f} m  contacts={sim.state.contact_count}"
    )
    for topic, count in sorted(counts.items()):
        print(f"  {topic}: {count} messages")
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="robodojo", description="RoboDojo remote robot lab")
    commands = parser.add_subparsers(dest="command", required=True)
    commands.add_parser("robots", help="list robots and their topics").set_defaults(
        func=_cmd_robots
    )
    commands.add_parser("worlds", help="list worlds").set_defaults(func=_cmd_worlds)
    run = commands.add_parser("run", help="drive a simulated robot with a constant command")
    run.add_argument("--robot", default="crowbot", help=f"one of {', '.join(robot_ids())}")
    run.add_argument("--world", default="wall_approach", help=f"one of {', '.join(world_ids())}")
    run.add_argument("--spawn", default=None, help="named spawn pose in the world")
    run.add_argument("--seed", type=int, default=0)
    run.add_argument("--duration", type=float, default=5.0, help="simulated seconds")
    run.add_argument("--linear", type=float, default=0.1, help="linear.x [m/s]")
    run.add_argument("--angular", type=float, default=0.0, help="angular.z [rad/s]")
    run.add_argument("--echo", action="append", default=[], help="print a topic's messages")
    run.set_defaults(func=_cmd_run)
    return parser


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return args.func(args)
    except ValueError as error:  # our errors are sentences; no traceback for a typo
        print(f"robodojo: {error}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    raise SystemExit(main())
