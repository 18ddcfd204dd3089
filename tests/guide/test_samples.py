"""Every controller shown in the student pages runs in the real sandbox, unchanged (issue 22):
each marked block is saved to a file and given to the `robodojo` command as a student would,
a short lockstep run (or, for the tutorial's controller, the exercise's grading, whose pass and
fail the page states). guide/samples.py says how blocks are marked."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from guide.samples import Sample, SampleError, samples

ROBODOJO = [sys.executable, "-m", "server.cli"]
ALL = samples()


def test_the_student_pages_have_samples_and_every_python_block_is_marked():
    assert len([s for s in ALL if not s.fragment]) >= 8
    pages = {s.page for s in ALL}
    assert {"controllers.md", "students/getting-started.md", "students/ros.md"} <= pages


def test_a_python_block_without_a_marker_is_refused(tmp_path):
    page = tmp_path / "students" / "x.md"
    page.parent.mkdir()
    page.write_text("# X\n\n```python\nprint('untested')\n```\n")
    from guide import samples as module

    with pytest.raises(SampleError, match="without a sample marker"):
        module.DOCS, saved = tmp_path, module.DOCS
        try:
            module.samples((page,))
        finally:
            module.DOCS = saved


def _summary(done: subprocess.CompletedProcess) -> dict:
    lines = done.stdout.strip().splitlines()
    assert lines, f"no output; stderr:\n{done.stderr}"
    return json.loads(lines[-1])


def _run(sample: Sample, tmp_path) -> None:
    code = tmp_path / "sample.py"
    code.write_text(sample.code)
    if "exercise" in sample.settings:
        done = subprocess.run(
            [*ROBODOJO, "check", sample.settings["exercise"], "--node", str(code)],
            capture_output=True, text=True, timeout=300, check=False,
        )  # fmt: skip
        result = _summary(done)
        passed = {c["name"] for c in result["checks"] if c["passed"]}
        failed = {c["name"] for c in result["checks"] if not c["passed"]}
        assert sample.names("passes") <= passed, (sample.where, result["checks"])
        assert sample.names("fails") <= failed, (sample.where, result["checks"])
        assert all(run["state"] == "finished" for run in result["runs"]), result["runs"]
        return
    done = subprocess.run(
        [*ROBODOJO, "run", "--robot", sample.settings["robot"], "--world",
         sample.settings["world"], "--node", f"sample={code}", "--duration",
         sample.settings["seconds"], "--clock", "lockstep", "--out", str(tmp_path / "run")],
        capture_output=True, text=True, timeout=300, check=False,
    )  # fmt: skip
    summary = _summary(done)
    assert done.returncode == 0 and summary["state"] == "finished", (
        f"{sample.where}: {summary.get('reason')}\n{done.stderr[-3000:]}"
    )
    # A callback's exception is logged and the node goes on (as in rospy): none may be there.
    for log in (tmp_path / "run").rglob("*.log"):
        assert "Traceback" not in log.read_text(), f"{sample.where}:\n{log.read_text()[-3000:]}"


RUNNABLE = [s for s in ALL if not s.fragment]


@pytest.mark.parametrize(
    "sample",
    # One sample stays in the fast loop; each is a sandboxed run of a few seconds.
    [pytest.param(s, marks=() if i == 0 else pytest.mark.slow) for i, s in enumerate(RUNNABLE)],
    ids=[s.where.removeprefix("docs/") for s in RUNNABLE],
)
def test_every_controller_in_the_student_pages_runs_unchanged(sample, tmp_path):
    _run(sample, tmp_path)
