"""Files the node writes are collected at the end, within the caps, with notes beyond them."""

from __future__ import annotations

import os
from pathlib import Path

from sandbox.artifacts import collect_artifacts, write_workspace_files
from sandbox.limits import Limits, MiB
from sandbox.protocol import Artifact, Outcome
from tests.sandbox.test_host_harness import Parent, run


def test_files_are_collected_relative_and_symlinks_and_hidden_files_skipped(
    tmp_path: Path,
) -> None:
    (tmp_path / "plots").mkdir()
    (tmp_path / "plots" / "a.csv").write_text("1,2\n")
    (tmp_path / "b.txt").write_text("hello")
    (tmp_path / ".matplotlib").mkdir()
    (tmp_path / ".matplotlib" / "fontlist.json").write_text("{}")
    os.symlink("/etc/hostname", tmp_path / "link")
    artifacts, notes = collect_artifacts(str(tmp_path))
    assert {(a.name, a.data) for a in artifacts} == {
        ("b.txt", b"hello"),
        (os.path.join("plots", "a.csv"), b"1,2\n"),
    }
    assert notes == []


def test_caps_skip_files_with_a_note(tmp_path: Path) -> None:
    limits = Limits(artifact_file_bytes=2 * MiB, artifact_total_bytes=3 * MiB, artifact_count=3)
    (tmp_path / "a_big.png").write_bytes(b"x" * int(2.5 * MiB))
    (tmp_path / "b.bin").write_bytes(b"y" * (2 * MiB))
    (tmp_path / "c.bin").write_bytes(b"z" * (2 * MiB))
    (tmp_path / "d.txt").write_text("small")
    (tmp_path / "e.txt").write_text("over count")
    artifacts, notes = collect_artifacts(str(tmp_path), limits)
    assert [a.name for a in artifacts] == ["b.bin", "d.txt", "e.txt"]
    assert notes == [
        "a_big.png (2.5 MB) skipped: over the 2 MB per-file cap",
        "c.bin (2 MB) skipped: over the 3 MB total cap for all files",
    ]
    (tmp_path / "f.txt").write_text("fourth")
    _, notes = collect_artifacts(str(tmp_path), limits)
    assert notes[-1] == "f.txt skipped: over the 3 file cap"


def test_a_run_reports_capped_files_in_exited_notes(tmp_path: Path) -> None:
    limits = Limits(artifact_file_bytes=1 * MiB)
    _, exited = run(
        """
        with open("figure_big.png", "wb") as f:
            f.write(b"0" * (3 * 1024 * 1024 + 200_000))
        with open("ok.txt", "w") as f:
            f.write("fine")
        """,
        tmp_path,
        limits=limits,
    )
    assert exited.outcome is Outcome.FINISHED
    assert [a.name for a in exited.artifacts] == ["ok.txt"]
    assert exited.notes == ["figure_big.png (3.2 MB) skipped: over the 1 MB per-file cap"]


def test_artifacts_are_collected_after_an_error_too(tmp_path: Path) -> None:
    parent = Parent("open('partial.csv', 'w').write('t,x\\n')\n1 / 0\n", tmp_path)
    exited = parent.next()
    assert exited.outcome is Outcome.ERROR
    assert [a.name for a in exited.artifacts] == ["partial.csv"]


def test_workspace_files_are_copied_in_and_only_changed_ones_come_back(tmp_path: Path) -> None:
    files = [
        Artifact("data/waypoints.csv", b"x,y\n1,2\n"),
        Artifact("gains.yaml", b"kp: 0.5\n"),
        Artifact("../escape.txt", b"no"),
        Artifact("/etc/passwd", b"no"),
        Artifact(".hidden/x", b"no"),
    ]
    inputs = write_workspace_files(str(tmp_path), files)
    assert sorted(inputs) == [os.path.join("data", "waypoints.csv"), "gains.yaml"]
    assert (tmp_path / "data" / "waypoints.csv").read_bytes() == b"x,y\n1,2\n"
    assert not (tmp_path.parent / "escape.txt").exists()
    (tmp_path / "gains.yaml").write_bytes(b"kp: 0.7\n")  # the node tuned its copy
    (tmp_path / "plot.png").write_bytes(b"png")
    artifacts, _ = collect_artifacts(str(tmp_path), inputs=inputs)
    assert {(a.name, a.data) for a in artifacts} == {
        ("gains.yaml", b"kp: 0.7\n"),
        ("plot.png", b"png"),
    }
