"""`robodojo`: the command line.

    robodojo robots                       # the robots, a line each (--topics for their topics)
    robodojo worlds                       # the worlds, a line each
    robodojo run --robot crowbot --world wall_approach --node examples/step_api/crowbot.py
    robodojo run --robot turtlebot3 --world maze --node follower=wall.py --param speed=0.2 \
                 --remap scan:=base_scan --args "_gain:=1.5"   # rosrun-style, per node
    robodojo run --robot turtlebot3 --world maze --launch pkg/launch/two.launch speed:=0.3
    robodojo run --robot crowbot --world wall_approach --launch pkg/launch/two.launch.py speed:=0.3
    robodojo run --robot crowbot --world wall_approach --node talker.py \
                 --args "--ros-args -p speed:=0.2 -r cmd_vel:=Control"   # a ROS 2 node's argv
    robodojo export RUN_DIR               # a CSV per topic from a run's recording
    robodojo serve                        # the web lab (server/api/serve.py)
    robodojo worker --redis-url URL --database-url URL   # a cluster's worker (server/workers)

`run` executes headless: a progress bar of simulated time on a terminal (plain lines when not a
TTY), the recording and artifacts written to --out, and one JSON summary as the last line of
standard output. Exit code 0 when the run finished, 1 when it failed or was interrupted (the
reason on stderr), 2 for a mistake in the command.
"""

from __future__ import annotations

import argparse
import json
import signal
import sys
import threading
import time
from pathlib import Path

from sandbox.bwrap import SandboxUnavailable
from sandbox.launcher import Launcher
from sandbox.protocol import Clock
from server.cli_nodes import (
    data_files,
    launch_arguments,
    node_file_spec,
    nodes_from_flags,
    read_workspace,
    workspace_folder,
)
from server.runs.launch import LaunchPlan
from server.runs.launch_py import is_python_launch, read_launch
from server.runs.run import Run
from server.runs.spec import NodeSpec, RunSpec, RunSpecError
from server.runs.state import RunState
from server.sim import get_robot, load_world, robot_ids, robots_for_world, world_ids
from server.sim.world import WorldError
from server.store.errors import StoreError

PROGRESS_WIDTH = 30  # [characters] of the progress bar


def _cmd_robots(args: argparse.Namespace) -> int:
    for robot_id in robot_ids():
        robot = get_robot(robot_id)
        print(f"{robot_id:<11} {robot.title}  [worlds: {', '.join(robots_for_world(robot_id))}]")
        if args.topics:
            for topic in robot.topics():
                rate = f" @ {topic.rate_hz:g} Hz" if topic.rate_hz else ""
                print(f"    {topic.direction:<9} {topic.name} [{topic.type_name}]{rate}: "
                      f"{topic.description}")  # fmt: skip
    return 0


def _cmd_worlds(_: argparse.Namespace) -> int:
    for world_id in world_ids():
        world = load_world(world_id)
        print(f"{world_id:<14} {world.title}  [robots: {', '.join(world.robots)}]")
    return 0


def _node_specs(values: list[str]) -> tuple[NodeSpec, ...]:
    """`--node FILE` or `--node NAME=FILE`, as in a launch file."""
    return tuple(node_file_spec(value) for value in values)


class _InOrder(argparse.Action):
    """Keeps --node/--param/--remap/--args/--ns in command-line order: a flag after a --node
    belongs to that node."""

    def __call__(self, parser, namespace, values, option_string=None) -> None:
        ordered = list(getattr(namespace, "ordered", None) or [])
        ordered.append((self.dest, values))
        namespace.ordered = ordered


def _nodes_and_files(args: argparse.Namespace) -> tuple[tuple[NodeSpec, ...], dict, tuple]:
    """The run's nodes, run-wide params and workspace data files, from --node flags or a
    --launch file."""
    ordered = args.ordered or []
    if args.launch is None:
        if args.workspace:
            raise ValueError("--workspace goes with --launch FILE")
        nodes, params = nodes_from_flags(ordered)
        if not nodes:
            raise ValueError("give the code to run: --node [NAME=]FILE (repeat) or --launch FILE")
        return nodes, params, ()
    if any(flag in ("node", "remap", "args", "ns") for flag, _ in ordered):
        raise ValueError(
            "--launch runs the nodes its file names; put remaps and arguments in the launch "
            "file (or use --node instead of --launch)"
        )
    launch_file, launch_args = Path(args.launch[0]), args.launch[1:]
    if not launch_file.is_file():
        raise ValueError(f"launch file '{launch_file}' does not exist (or is not a file)")
    folder = Path(args.workspace) if args.workspace else workspace_folder(launch_file)
    try:
        relative = launch_file.resolve().relative_to(folder.resolve()).as_posix()
    except ValueError:
        raise ValueError(
            f"launch file '{launch_file}' is not inside the workspace '{folder}'"
        ) from None
    workspace = read_workspace(folder)
    plan = _read_plan(relative, workspace, launch_arguments(launch_args), args.unsafe_no_sandbox)
    _, run_params = nodes_from_flags(ordered)  # --param NAME=VALUE: run-wide, as before
    for note in plan.notes:
        print(f"robodojo: note: {note}", file=sys.stderr)
    return plan.nodes, {**plan.params, **run_params}, data_files(workspace)


def _read_plan(
    relative: str, workspace: dict[str, bytes], launch_args: dict[str, str], unsafe: bool
) -> LaunchPlan:
    """A ROS 1 launch file is read here; a ROS 2 Python launch file is student code, run in a
    sandboxed launch job of its own (server/runs/launch_py.py)."""
    if not is_python_launch(relative, workspace.get(relative)):
        return read_launch(relative, workspace, launch_args, None)
    launcher = Launcher(pool_size=0, unsafe_no_sandbox=unsafe)
    try:
        return read_launch(relative, workspace, launch_args, launcher)
    finally:
        launcher.close()


class Progress:
    """A bar of simulated time on a terminal; a line every 10% otherwise."""

    def __init__(self, run: Run, stream=sys.stderr) -> None:
        self.run = run
        self.stream = stream
        self.tty = stream.isatty()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._loop, daemon=True)
        self._last_tenth = -1

    def __enter__(self) -> Progress:
        self._thread.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self._stop.set()
        self._thread.join()
        if self.tty:
            self.stream.write("\n")

    def _loop(self) -> None:
        while not self._stop.wait(0.1 if self.tty else 0.5):
            now, total = self.run.progress
            fraction = min(1.0, now / total) if total else 1.0
            if self.tty:
                filled = round(fraction * PROGRESS_WIDTH)
                bar = "#" * filled + "-" * (PROGRESS_WIDTH - filled)
                self.stream.write(f"\r[{bar}] {now:7.2f} / {total:g} s  {self.run.state}")
                self.stream.flush()
            elif int(fraction * 10) > self._last_tenth:
                self._last_tenth = int(fraction * 10)
                self.stream.write(f"progress: {now:.1f} / {total:g} s\n")


def _cmd_run(args: argparse.Namespace) -> int:
    nodes, params, files = _nodes_and_files(args)
    spec = RunSpec(
        robot=args.robot,
        world=args.world,
        nodes=nodes,
        clock=Clock(args.clock),
        duration_s=args.duration,
        seed=args.seed,
        spawn=args.spawn,
        params=params,
        files=files,
    )
    spec.validate()
    out_dir = (
        Path(args.out)
        if args.out
        else Path("robodojo-data") / "runs" / time.strftime("%Y%m%d-%H%M%S")
    )
    # No warm pool for one run: a cold node is ready in ~0.1 s and imports only what its code
    # does, while pool processes preload every heavy library and compete for the cores
    # (`robodojo run` of examples/step_api/crowbot.py for 60 s: median 1.42 s against 1.83 s).
    launcher = Launcher(pool_size=0, unsafe_no_sandbox=args.unsafe_no_sandbox)
    try:
        run = Run(spec, launcher, out_dir)
        # Ctrl-C ends the run cleanly (nodes shut down, recording closed) instead of killing it.
        signal.signal(signal.SIGINT, lambda *_: run.stop("interrupted from the keyboard"))
        with Progress(run):
            result = run.execute()
    finally:
        launcher.close()
    for name, slot in run.slots.items():
        if slot.exited is not None and slot.exited.error is not None:
            print(f"--- node {name} ---", file=sys.stderr)
            print(slot.exited.error.traceback.rstrip(), file=sys.stderr)
    if result.state is not RunState.FINISHED:
        print(f"robodojo: {result.reason}", file=sys.stderr)
    print(json.dumps(result.summary()))
    return 0 if result.state is RunState.FINISHED else 1


def _cmd_exercises(_: argparse.Namespace) -> int:
    from server.exercises.registry import exercise_ids, get_exercise

    for exercise_id in exercise_ids():
        exercise = get_exercise(exercise_id)
        print(f"{exercise_id:<22} {exercise.title}  [{exercise.robot} in {exercise.world}]")
    return 0


def _cmd_check(args: argparse.Namespace) -> int:
    from server.exercises.grading import grade, reference_nodes, starter_nodes
    from server.exercises.registry import get_exercise

    exercise = get_exercise(args.exercise)
    if sum(bool(x) for x in (args.node, args.reference, args.starter)) != 1:
        raise ValueError("give the code to check: --node FILE [...], --reference or --starter")
    if args.reference:
        nodes = reference_nodes(exercise)
    elif args.starter:
        nodes = starter_nodes(exercise)
    else:
        nodes = _node_specs(args.node)
    # Each seed's run in a worker process forked from this one, with its own launcher.
    clock = Clock(args.clock) if args.clock else None
    out_dir = Path(args.out) if args.out else None
    try:
        result = grade(exercise, nodes, None, out_dir, clock, args.unsafe_no_sandbox)
    except KeyboardInterrupt:  # Ctrl-C reaches the workers too: their runs end with them
        print("robodojo: check interrupted from the keyboard; no grade", file=sys.stderr)
        return 1
    for run in result.runs:
        if run["state"] != RunState.FINISHED:
            print(f"seed {run['seed']}: {run['reason']}", file=sys.stderr)
    for check in result.checks:
        verdict = "pass" if check.passed else "FAIL"
        print(
            f"{verdict}  {check.name:<22} {check.value:10.4g} {check.unit:<2} "
            f"(needs {check.comparison} {check.threshold:g})  {check.description}"
        )
    print(json.dumps(result.summary()))
    return 0 if result.passed else 1


def _cmd_export(args: argparse.Namespace) -> int:
    from server.runs.export import export_csv

    run_dir = Path(args.run_dir)
    recording = run_dir / "recording.mcap"
    if not recording.is_file():
        raise ValueError(f"'{run_dir}' holds no recording.mcap; give the --out folder of a run")
    written = export_csv(recording, Path(args.out) if args.out else run_dir / "csv")
    for path in written:
        print(path)
    return 0


def _positive_seconds(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a number of seconds") from None
    if not value > 0:
        raise argparse.ArgumentTypeError(f"a duration must be positive, got {text}")
    return value


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="robodojo", description="RoboDojo remote robot lab")
    commands = parser.add_subparsers(dest="command", required=True)
    robots = commands.add_parser("robots", help="list the robots")
    robots.add_argument("--topics", action="store_true", help="also list each robot's topics")
    robots.set_defaults(func=_cmd_robots)
    commands.add_parser("worlds", help="list the worlds").set_defaults(func=_cmd_worlds)

    run = commands.add_parser("run", help="run controller nodes against a simulated robot")
    run.add_argument("--robot", required=True, help=f"one of {', '.join(robot_ids())}")
    run.add_argument("--world", required=True, help=f"one of {', '.join(world_ids())}")
    run.add_argument(
        "--node",
        action=_InOrder,
        metavar="[NAME=]FILE",
        help="a controller file; repeat for several nodes",
    )
    run.add_argument(
        "--param",
        action=_InOrder,
        metavar="NAME=VALUE",
        help="a parameter (YAML-typed): after a --node that node's own (~NAME), before any "
        "--node run-wide",
    )
    run.add_argument("--remap", action=_InOrder, metavar="FROM:=TO", help="rename a topic")
    run.add_argument(
        "--args",
        action=_InOrder,
        metavar='"ARGS"',
        help="the node's command line, as rosrun's (--args=\"--flag\" for one starting with -)",
    )
    run.add_argument("--ns", action=_InOrder, metavar="NAMESPACE", help="the node's namespace")
    run.add_argument(
        "--launch",
        nargs="+",
        default=None,
        metavar=("FILE", "NAME:=VALUE"),
        help="a launch file (ROS 2 .launch.py or ROS 1 .launch), then its arguments as ros2 "
        "launch and roslaunch take them (name:=value)",
    )
    run.add_argument(
        "--workspace",
        default=None,
        metavar="DIR",
        help="the folder the launch file's nodes and data come from (default: its package)",
    )
    run.add_argument("--duration", type=_positive_seconds, default=30.0, help="seconds")
    run.add_argument("--clock", choices=[c.value for c in Clock], default=Clock.LOCKSTEP.value)
    run.add_argument("--seed", type=int, default=0)
    run.add_argument("--spawn", default=None, help="a named start pose of the world")
    run.add_argument("--out", default=None, help="folder for the recording, logs, artifacts")
    run.add_argument(
        "--unsafe-no-sandbox",
        action="store_true",
        help="DANGER: run student code without bubblewrap (trusted code on a laptop only)",
    )
    run.set_defaults(func=_cmd_run, ordered=None)

    commands.add_parser("exercises", help="list the exercises").set_defaults(func=_cmd_exercises)
    check = commands.add_parser("check", help="run an exercise headless and grade it")
    check.add_argument("exercise", help="an exercise id (see `robodojo exercises`)")
    check.add_argument("--node", action="append", default=[], metavar="[NAME=]FILE")
    check.add_argument("--reference", action="store_true", help="check the reference solution")
    check.add_argument("--starter", action="store_true", help="check the starter code")
    check.add_argument("--out", default=None, help="folder for the runs' recordings")
    check.add_argument(
        "--clock",
        choices=[str(c) for c in Clock],
        default=None,
        help="run on this clock instead of the exercise's (lockstep or realtime)",
    )
    check.add_argument("--unsafe-no-sandbox", action="store_true", help=argparse.SUPPRESS)
    check.set_defaults(func=_cmd_check)

    export = commands.add_parser("export", help="write a CSV per topic from a run's recording")
    export.add_argument("run_dir", help="the --out folder of a run")
    export.add_argument("--out", default=None, help="folder for the CSV files")
    export.set_defaults(func=_cmd_export)

    from server.api.serve import add_commands

    add_commands(commands)
    from server.workers.cli import add_command as add_worker_command

    add_worker_command(commands)
    for command_parser in commands.choices.values():
        command_parser.set_defaults(command_parser=command_parser)
    return parser


def main(argv: list[str] | None = None) -> int:
    args, unknown = build_parser().parse_known_args(argv)
    if unknown:
        # The command's own usage and sentence (`robodojo serve: error: unrecognized arguments:
        # --prot 8765`), not the top level's, which names no option the user could mean.
        args.command_parser.error(f"unrecognized arguments: {' '.join(unknown)}")
    try:
        return args.func(args)
    except (RunSpecError, WorldError, SandboxUnavailable, StoreError, ValueError) as error:
        # Our errors are sentences: no traceback for a typo.
        print(f"robodojo: {error}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    raise SystemExit(main())
