"""Issue 33, finding 7: the artifact caps held only inside the sandbox. A node that replaced its
own `collect_artifacts` sent 20,002 files, or one of 40 MiB, and the server wrote them all; one
student's runs reached 960 MiB against a 500 MiB budget. Here such a node runs in a real
sandbox, in a real run: the server keeps at most the caps' worth (sandbox/limits.py) and the
run's log says what it refused."""

from __future__ import annotations

from pathlib import Path

import pytest

from sandbox import bwrap
from sandbox.launcher import Launcher
from sandbox.limits import DEFAULT_LIMITS
from server.runs.run import Run
from server.runs.spec import NodeSpec, RunSpec
from server.runs.state import RunState
from tests.sandbox.conftest import TEST_LIMITS

FLOOD = """\
import sandbox.host
from sandbox.protocol import Artifact


def flood(workdir, limits, inputs):
    files = [Artifact("big.bin", b"\\0" * (40 * 1024 * 1024))]
    files += [Artifact(f"f{i:05d}.txt", b"x" * 100) for i in range(20_000)]
    files += [Artifact("../../../escape.txt", b"out"), Artifact("/etc/x", b"out")]
    return files, ["collected"] * 10_000


sandbox.host.collect_artifacts = flood
print("collector replaced")
"""


@pytest.fixture(scope="module")
def launcher():
    problem = bwrap.probe()
    if problem:
        pytest.fail(f"the security tests need bubblewrap: {problem}")
    launcher = Launcher(limits=TEST_LIMITS, pool_size=0)
    yield launcher
    launcher.close()


def test_a_node_that_replaces_its_collector_gets_only_the_caps_worth_written(
    tmp_path: Path, launcher: Launcher
) -> None:
    spec = RunSpec(
        robot="crowbot", world="wall_approach", nodes=(NodeSpec("flood", FLOOD, "flood.py"),),
        duration_s=1.0,
    )  # fmt: skip
    result = Run(spec, launcher, tmp_path / "run").execute()
    assert result.state is RunState.FINISHED, result.reason
    log = (tmp_path / "run/logs/flood.log").read_text()
    assert "collector replaced" in log
    files = [path for path in (tmp_path / "run/artifacts").rglob("*") if path.is_file()]
    sizes = [path.stat().st_size for path in files]
    assert len(files) == DEFAULT_LIMITS.artifact_count, len(files)
    assert max(sizes) <= DEFAULT_LIMITS.artifact_file_bytes
    assert sum(sizes) <= DEFAULT_LIMITS.artifact_total_bytes
    assert not list(tmp_path.rglob("escape.txt")) and not (tmp_path / "run/artifacts/etc").exists()
    lines = log.splitlines()
    assert "[artifacts] big.bin (40 MB) refused by the server: over the 8 MB per-file cap" in lines
    assert "[artifacts] 19968 more files refused by the server: over the 32 file cap" in lines
    assert (
        "[artifacts] ../../../escape.txt refused by the server: its name is not a path inside "
        "the node's folder"
    ) in lines
    assert sum("[artifacts]" in line for line in lines) < 80  # not 10,000 notes


SAVER = """\
with open("{name}.bin", "wb") as out:
    out.write(b"\\0" * (7 * 1024 * 1024))
with open("{name}_2.bin", "wb") as out:
    out.write(b"\\0" * (7 * 1024 * 1024))
"""


def test_the_total_cap_holds_for_a_runs_nodes_together(tmp_path: Path, launcher: Launcher) -> None:
    """Three nodes of 14 MiB each, honestly collected: the run keeps 24 MiB, not 42."""
    nodes = tuple(NodeSpec(name, SAVER.format(name=name), f"{name}.py") for name in ("a", "b", "c"))
    spec = RunSpec(robot="crowbot", world="wall_approach", nodes=nodes, duration_s=1.0)
    result = Run(spec, launcher, tmp_path / "run").execute()
    assert result.state is RunState.FINISHED, result.reason
    files = sorted(p for p in (tmp_path / "run/artifacts").rglob("*") if p.is_file())
    assert sum(p.stat().st_size for p in files) <= DEFAULT_LIMITS.artifact_total_bytes
    assert [p.relative_to(tmp_path / "run/artifacts").as_posix() for p in files] == [
        "a/a.bin", "a/a_2.bin", "b/b.bin",
    ]  # fmt: skip
    logs = (tmp_path / "run/logs/b.log").read_text() + (tmp_path / "run/logs/c.log").read_text()
    assert (
        "[artifacts] b_2.bin (7 MB) refused by the server: over the 24 MB the nodes of a run may "
        "save"
    ) in logs.splitlines()
