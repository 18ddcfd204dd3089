"""The server's check of the files a node sends (sandbox/artifact_intake.py): whatever the
node's collector did, only files within the caps and with names the collector could have made
are kept, and every refusal is said in a note."""

from __future__ import annotations

from sandbox.artifact_intake import NOTES_KEPT, accept_artifacts, name_problem, within_run_room
from sandbox.limits import Limits, MiB
from sandbox.protocol import Artifact, Exited, Outcome

LIMITS = Limits(artifact_file_bytes=2 * MiB, artifact_total_bytes=3 * MiB, artifact_count=3)


def exited(*artifacts: Artifact, notes: tuple[str, ...] = ()) -> Exited:
    return Exited(outcome=Outcome.FINISHED, reason="", artifacts=list(artifacts), notes=[*notes])


def test_what_the_collector_would_send_passes_unchanged():
    sent = exited(Artifact("plots/a.png", b"png"), Artifact("log.csv", b"t,x\n"), notes=("n",))
    assert accept_artifacts(sent, LIMITS) == sent


def test_each_cap_refuses_with_a_note():
    kept = accept_artifacts(
        exited(
            Artifact("a_big.png", b"x" * int(2.5 * MiB)),
            Artifact("b.bin", b"y" * (2 * MiB)),
            Artifact("c.bin", b"z" * (2 * MiB)),
            Artifact("d.txt", b"small"),
            Artifact("e.txt", b"third"),
            Artifact("f.txt", b"fourth"),
            Artifact("g.txt", b"fifth"),
        ),
        LIMITS,
    )
    assert [a.name for a in kept.artifacts] == ["b.bin", "d.txt", "e.txt"]
    assert kept.notes == [
        "a_big.png (2.5 MB) refused by the server: over the 2 MB per-file cap",
        "c.bin (2 MB) refused by the server: over the 3 MB total cap for all files",
        "2 more files refused by the server: over the 3 file cap",
    ]


def test_names_the_collector_could_not_have_made_are_refused():
    bad = ["", "../escape", "/etc/passwd", "a//b", "a/./b", ".hidden", "d/.x", "a\nb", "x" * 1025]
    for name in bad:
        assert name_problem(name, Limits()) is not None, name
    for name in ["plot.png", "runs/2026/a b.csv", "ü.txt", "a\\b"]:
        assert name_problem(name, Limits()) is None, name
    kept = accept_artifacts(
        exited(Artifact("ok.txt", b"1"), Artifact("ok.txt", b"2"), Artifact("../up", b"3")),
        LIMITS,
    )
    assert [(a.name, a.data) for a in kept.artifacts] == [("ok.txt", b"1")]
    assert kept.notes == [
        "ok.txt refused by the server: a file of that name came already",
        "../up refused by the server: its name is not a path inside the node's folder",
    ]


def test_twenty_thousand_files_and_notes_leave_a_few_lines():
    """The attack of issue 33, finding 7: a node whose collector was replaced sent 20,002
    files (and may send as many notes)."""
    files = [Artifact(f"f{i:05d}.txt", b"x") for i in range(20_000)]
    files += [Artifact(f"bad/../{i}", b"x") for i in range(2)]
    kept = accept_artifacts(exited(*files, notes=tuple(["noise " * 2000] * 5000)), Limits())
    assert len(kept.artifacts) == 32
    assert len(kept.notes) == NOTES_KEPT + 1 + 2 + 1  # the node's, a count, 2 names, a count
    assert all(len(note) <= Limits().log_line_bytes for note in kept.notes)
    assert kept.notes[NOTES_KEPT] == f"{5000 - NOTES_KEPT} more notes of the node left out"
    assert kept.notes[-1] == "19968 more files refused by the server: over the 32 file cap"


def test_what_the_runs_other_nodes_left_is_the_room():
    files = (Artifact("a.bin", b"a" * MiB), Artifact("b.bin", b"b" * MiB))
    kept = within_run_room(exited(*files, notes=("n",)), LIMITS, room_bytes=MiB + 10)
    assert [a.name for a in kept.artifacts] == ["a.bin"]
    assert kept.notes == [
        "n",
        "b.bin (1 MB) refused by the server: over the 3 MB the nodes of a run may save",
    ]
    assert within_run_room(exited(*files), LIMITS, room_bytes=0).artifacts == []
    assert within_run_room(exited(*files), LIMITS, room_bytes=2 * MiB) == exited(*files)
