"""The exercise registry and grading: every entry valid, every reference solution passes its own
checks on five seeds, every starter runs and fails at least one check (so the checks can fail)."""

from __future__ import annotations

import dataclasses
import json
import os
import signal
import subprocess
import sys
from pathlib import Path

import psutil
import pytest

from server.exercises.grading import cases_of, grade, reference_nodes, starter_nodes
from server.exercises.registry import (
    UnknownExerciseError,
    exercise_ids,
    get_exercise,
    validate_exercise,
)
from server.runs.state import RunState
from tests.waiting import wait_until

FIVE_SEEDS = (1, 2, 3, 4, 5)
# The fast set (-m "not slow") grades one quick starter; the rest take seconds each.
FAST_STARTERS = ("crowbot_data_logger",)


@pytest.mark.parametrize("exercise_id", exercise_ids())
def test_registry_entries_are_valid(exercise_id):
    assert validate_exercise(get_exercise(exercise_id)) == []


@pytest.mark.parametrize("exercise_id", exercise_ids())
def test_every_exercise_names_its_leaderboard_key_figure(exercise_id):
    """Leaderboards rank equal scores by it: a registry exercise without one ranks by who was
    first, which tells students nothing about how good their controller is."""
    assert get_exercise(exercise_id).key_check() is not None


def test_a_leaderboard_check_that_is_no_check_is_refused():
    exercise = dataclasses.replace(get_exercise("crowbot_distance_pid"), leaderboard_check="speed")
    problems = validate_exercise(exercise)
    assert len(problems) == 1 and "leaderboard_check 'speed'" in problems[0]
    assert "settling_time" in problems[0]  # the checks it could name


def test_a_check_that_cannot_reach_a_worker_process_is_refused():
    exercise = get_exercise("crowbot_distance_pid")
    closure = dataclasses.replace(exercise.checks[0], metric=lambda evidence: 0.0)
    problems = validate_exercise(dataclasses.replace(exercise, checks=(closure,)))
    assert len(problems) == 1 and "module-level function, not a lambda" in problems[0]


def test_unknown_exercise_lists_the_valid_ids():
    with pytest.raises(UnknownExerciseError, match="crowbot_distance_pid"):
        get_exercise("crowbot_distnce_pid")


@pytest.mark.slow
@pytest.mark.parametrize("exercise_id", exercise_ids())
def test_reference_passes_on_five_seeds(exercise_id, tmp_path):
    exercise = dataclasses.replace(get_exercise(exercise_id), seeds=FIVE_SEEDS)
    result = grade(exercise, reference_nodes(exercise), None, tmp_path)  # as robodojo check does
    failed = [(c.name, c.per_seed, c.threshold) for c in result.checks if not c.passed]
    assert result.passed, (failed, [r["reason"] for r in result.runs])


@pytest.mark.parametrize(
    "exercise_id",
    [pytest.param(i, marks=() if i in FAST_STARTERS else pytest.mark.slow) for i in exercise_ids()],
)
def test_starter_runs_and_fails_a_check(exercise_id, launcher, tmp_path):
    exercise = get_exercise(exercise_id)
    result = grade(exercise, starter_nodes(exercise), launcher, tmp_path)
    assert all(run["state"] == RunState.FINISHED for run in result.runs), result.runs
    assert not all(check.passed for check in result.checks)


@pytest.mark.slow
def test_check_command_grades_and_sets_the_exit_code(tmp_path):
    command = [sys.executable, "-m", "server.cli", "check", "crowbot_distance_pid"]
    passed = subprocess.run([*command, "--reference"], capture_output=True, text=True, timeout=120)
    assert passed.returncode == 0, passed.stderr
    lines = passed.stdout.strip().splitlines()
    assert lines[0].startswith("pass  settling_time")
    assert json.loads(lines[-1])["passed"] is True
    failed = subprocess.run([*command, "--starter"], capture_output=True, text=True, timeout=120)
    assert failed.returncode == 1
    assert "FAIL  steady_state_error" in failed.stdout
    nothing = subprocess.run(command, capture_output=True, text=True, timeout=60)
    assert nothing.returncode == 2
    assert "--node FILE [...], --reference or --starter" in nothing.stderr


def _command_line(process: psutil.Process) -> str:
    """The process's command line; "" for one that is ending (a zombie not yet reaped: the CLI's
    short-lived helpers are, for a moment) or gone."""
    try:
        return " ".join(process.cmdline())
    except psutil.Error:
        return ""


def _alive(process: psutil.Process) -> bool:
    """Running, and not a zombie waiting to be reaped (its work is over)."""
    try:
        return process.is_running() and process.status() != psutil.STATUS_ZOMBIE
    except psutil.Error:
        return False


# A node that never ends its part: on the realtime clock a run lasts its duration in wall time
# (crop_row_fuzzy's 120 s), so the check cannot finish before the Ctrl-C reaches it, however
# slowly a loaded machine gets there. Its log line says that its run is underway.
UNDERWAY = "running until the check is interrupted"
UNTIL_INTERRUPTED = f"""\
import rospy

rospy.init_node("until_interrupted")
rospy.loginfo("{UNDERWAY}")
rospy.spin()
"""


def _runs_underway(runs: Path) -> int:
    """How many of a check's runs (in its --out folder `runs`) have their node running."""
    logs = runs.glob("*/logs/until_interrupted.log")
    return sum(UNDERWAY in log.read_text() for log in logs)


@pytest.mark.slow
def test_check_interrupted_from_the_keyboard_says_so_and_leaves_no_process(tmp_path):
    node = tmp_path / "until_interrupted.py"
    node.write_text(UNTIL_INTERRUPTED)
    runs = tmp_path / "runs"
    command = [sys.executable, "-m", "server.cli", "check", "crop_row_fuzzy", "--clock=realtime"]
    command += ["--node", str(node), "--out", str(runs)]
    # A suite started in the background by a shell without job control ignores SIGINT, and an
    # ignored signal stays ignored across exec: the check would never hear the Ctrl-C and would
    # grade. A handled one is reset to the default, as a terminal's foreground job has it.
    handler = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        check = subprocess.Popen(
            command,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            start_new_session=True,
        )
    finally:
        signal.signal(signal.SIGINT, signal.SIG_DFL if handler is None else handler)
    cli = psutil.Process(check.pid)
    # Every run underway: each worker has left the check's process group (one the Ctrl-C caught
    # still in it would print a traceback of its own) and started its node.
    each_run = len(cases_of(get_exercise("crop_row_fuzzy")))
    try:
        wait_until(
            lambda: _runs_underway(runs) == each_run,
            60,
            f"the node of each of the check's {each_run} runs is running",
        )
        # Its workers, their sandboxes and nodes, named while they run.
        processes = {p: _command_line(p) for p in cli.children(recursive=True)}
        os.killpg(check.pid, signal.SIGINT)  # Ctrl-C in a terminal: the whole process group
        out, err = check.communicate(timeout=60)
    finally:  # a failed wait must not leave the check running, nor its pipes to the collector
        if check.poll() is None:
            os.killpg(check.pid, signal.SIGKILL)
            check.communicate(timeout=60)
    assert check.returncode == 1, err
    assert err.strip().splitlines()[-1] == (
        "robodojo: check interrupted from the keyboard; no grade"
    )
    assert "Traceback" not in err and out == ""
    assert any("server.cli" in line for line in processes.values()), processes
    assert any("bwrap" in line for line in processes.values()), processes
    wait_until(
        lambda: not any(_alive(p) for p in processes), 30, "the workers and their nodes ended"
    )
