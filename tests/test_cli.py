"""The `robodojo` command as a newcomer uses it: listings, a headless run, and the mistakes."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

ROBODOJO = [sys.executable, "-m", "server.cli"]


def robodojo(*args: str, timeout: float = 120.0) -> subprocess.CompletedProcess:
    return subprocess.run(
        [*ROBODOJO, *args], capture_output=True, text=True, timeout=timeout, check=False
    )


def test_listings_have_a_line_each():
    robots = robodojo("robots").stdout.splitlines()
    assert [line.split()[0] for line in robots] == [
        "crop_rover",
        "crowbot",
        "ir_scout",
        "turtlebot",
        "turtlebot3",
    ]
    worlds = robodojo("worlds").stdout.splitlines()
    assert len(worlds) == 6 and worlds[0].startswith("crop_rows")


def test_headless_run_prints_a_json_summary_last(tmp_path):
    out = tmp_path / "run"
    done = robodojo(
        "run", "--robot", "crowbot", "--world", "wall_approach",
        "--node", "examples/step_api/crowbot.py", "--duration", "5", "--out", str(out),
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    summary = json.loads(done.stdout.strip().splitlines()[-1])
    assert summary["state"] == "finished"
    assert summary["reason"] == "finished: duration reached"
    assert summary["nodes"]["crowbot"]["period"]["p50_s"] == pytest.approx(0.05)
    assert (out / "recording.mcap").is_file() and (out / "metrics.json").is_file()
    exported = robodojo("export", str(out))
    assert exported.returncode == 0, exported.stderr
    assert (out / "csv" / "Distance.csv").is_file()


@pytest.mark.slow
def test_failed_run_exits_non_zero_with_the_reason(tmp_path):
    crash = tmp_path / "crash.py"
    crash.write_text("def step(obs):\n    return {}['nothing']\n")
    done = robodojo(
        "run", "--robot", "crowbot", "--world", "wall_approach", "--node", f"crasher={crash}",
        "--duration", "2", "--out", str(tmp_path / "run"),
    )  # fmt: skip
    assert done.returncode == 1
    assert "robodojo: failed: node crasher raised KeyError at line 2" in done.stderr
    assert 'File "crash.py", line 2, in step' in done.stderr
    assert json.loads(done.stdout.strip().splitlines()[-1])["state"] == "failed"


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--robot", "crowbotz"], "unknown robot 'crowbotz'; valid robot ids: crop_rover"),
        # Each case starts the CLI (seconds): the fast set (-m "not slow") keeps the first.
        *(
            pytest.param(*case, marks=pytest.mark.slow)
            for case in (
                (["--world", "moon"], "unknown world 'moon'; valid world ids: crop_rows"),
                (["--world", "crop_rows"], "robot 'crowbot' cannot be placed in world 'crop_rows'"),
                (["--node", "missing.py"], "node file 'missing.py' does not exist"),
                (["--duration", "-3"], "a duration must be positive"),
                (["--duration", "soon"], "'soon' is not a number of seconds"),
            )
        ),
    ],
)
def test_newcomer_mistakes_get_a_sentence_not_a_traceback(args, message):
    base = {"--robot": "crowbot", "--world": "wall_approach",
            "--node": "examples/step_api/crowbot.py", "--duration": "1"}  # fmt: skip
    base[args[0]] = args[1]
    done = robodojo("run", *[item for pair in base.items() for item in pair])
    assert done.returncode == 2
    assert message in done.stderr
    assert "Traceback" not in done.stderr
