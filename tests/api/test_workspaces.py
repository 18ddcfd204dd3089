"""Workspaces: an exercise's starter code until the first save, every save a version (identical
saves are one), restoring an old version saves it again as the newest."""

from __future__ import annotations


def test_a_workspace_starts_from_the_starter_code_and_keeps_every_version(lab):
    student = lab.student("saver")
    exercise = student.get("/api/exercises/ir_scout_avoidance").json()
    fresh = student.get("/api/workspaces/ir_scout_avoidance").json()["files"]
    starter = {f"{s['name']}.py": s["code"] for s in exercise["starter"]}
    assert len(starter) == 4  # the paper's four nodes, a file each
    assert {f["filename"]: f["code"] for f in fresh} == starter
    assert all(f["version"] == 0 for f in fresh)

    url = "/api/workspaces/ir_scout_avoidance/files/planner.py"
    assert student.put(url, json={"code": "v = 1\n"}).json()["version"] == 1
    assert student.put(url, json={"code": "v = 1\n"}).json()["version"] == 1  # autosave, same
    assert student.put(url, json={"code": "v = 2\n"}).json()["version"] == 2
    versions = student.get(f"{url}/versions").json()["versions"]
    assert [v["version"] for v in versions] == [2, 1] and "code" not in versions[0]
    assert student.get(f"{url}/versions/1").json()["code"] == "v = 1\n"

    restored = student.post(f"{url}/versions/1/restore").json()
    assert (restored["version"], restored["code"]) == (3, "v = 1\n")
    files = student.get("/api/workspaces/ir_scout_avoidance").json()["files"]
    versions = {f["filename"]: f["version"] for f in files}
    assert versions.pop("planner.py") == 3
    assert set(versions) == set(starter) - {"planner.py"} and set(versions.values()) == {0}
    assert student.get(f"{url}/versions/9").status_code == 404


def test_deleting_a_file_removes_it_and_its_history(lab):
    student = lab.student("tidy")
    url = "/api/workspaces/crowbot/files/scratch.py"
    student.put(url, json={"code": "a = 1\n"})
    student.put(url, json={"code": "a = 2\n"})
    other = lab.student("untidy")
    assert other.delete(url).status_code == 404  # not theirs: nothing to delete
    answer = student.delete(url)
    assert answer.json() == {"ok": True, "versions_removed": 2}
    assert student.get("/api/workspaces/crowbot").json()["files"] == []
    assert student.delete(url).status_code == 404


def test_a_workspace_must_name_an_exercise_or_a_robot(lab):
    student = lab.student("wanderer")
    assert student.get("/api/workspaces/crop_rover").json()["files"] == []
    answer = student.get("/api/workspaces/cooking")
    assert answer.status_code == 404
    assert "crowbot" in answer.json()["valid"] and "crowbot_distance_pid" in answer.json()["valid"]
    too_many = [
        student.put(f"/api/workspaces/crowbot/files/f{i}.py", json={"code": ""}).status_code
        for i in range(33)
    ]
    assert too_many[:32] == [200] * 32 and too_many[32] == 422


def test_history_is_pruned_oldest_first_and_the_listing_says_so(lab):
    """Issue 33, finding 9: saves of a large data file keep the newest 8 MiB of history (the
    default cap), not every version; the listing says which versions were pruned."""
    student = lab.student("big-saver")
    url = "/api/workspaces/crowbot/files/map.csv"
    for n in range(12):
        body = f"{n:02d}," + "1" * 1_000_000
        assert student.put(url, json={"code": body}).status_code == 200
    listing = student.get(f"{url}/versions").json()
    numbers = [v["version"] for v in listing["versions"]]
    assert numbers == list(range(12, 12 - len(numbers), -1))  # the newest, none skipped
    assert (
        sum(v["bytes"] for v in listing["versions"]) <= 8 * 1024 * 1024 < len(numbers) * 1e6 + 1e6
    )
    assert listing["pruned"] and listing["oldest_kept"] == numbers[-1] > 1
    assert listing["kept"] == {"versions_per_file": 200, "workspace_bytes": 8 * 1024 * 1024}
    assert student.get(f"{url}/versions/1").status_code == 404  # pruned
