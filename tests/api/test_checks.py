"""A check from the student page: one run per grading case of an exercise (POST /api/runs with
`case`), summed up by GET /api/exercises/{id}/check the way `robodojo check` judges (each check
by its worst case), with the refusals a wrong request gets."""

from __future__ import annotations

import math

from tests.api.conftest import wait_for_end

EXERCISE = "crowbot_distance_pid"  # three seeds, so three cases


def starter_nodes(client) -> list[dict]:
    exercise = client.get(f"/api/exercises/{EXERCISE}").json()
    return [{"name": s["name"], "code": s["code"]} for s in exercise["starter"]]


def start_case(client, nodes: list[dict], case: int, **extra) -> object:
    body = {"exercise": EXERCISE, "nodes": nodes, "case": case, "clock": "lockstep", **extra}
    return client.post("/api/runs", json=body)


def test_a_check_runs_every_case_and_is_judged_by_its_worst_case(lab) -> None:
    client = lab.student("checker")
    exercise = client.get(f"/api/exercises/{EXERCISE}").json()
    cases = exercise["cases"]
    assert [c["seed"] for c in cases] == [1, 2, 3]
    nodes = starter_nodes(client)

    first = start_case(client, nodes, 0)
    assert first.status_code == 201, first.text
    assert first.json()["seed"] == cases[0]["seed"]
    partial = client.get(f"/api/exercises/{EXERCISE}/check", params={"runs": first.json()["id"]})
    assert partial.status_code == 200, partial.text
    assert partial.json()["cases"] == 3 and partial.json()["passed"] is None

    run_ids = [first.json()["id"]]
    wait_for_end(client, run_ids[0], timeout_s=120)
    for case in (1, 2):  # one at a time: the student's run limit is the page's to respect
        answer = start_case(client, nodes, case)
        assert answer.status_code == 201, answer.text
        assert answer.json()["seed"] == cases[case]["seed"]
        run_ids.append(answer.json()["id"])
        wait_for_end(client, run_ids[-1], timeout_s=120)

    summary = client.get(f"/api/exercises/{EXERCISE}/check", params={"runs": ",".join(run_ids)})
    assert summary.status_code == 200, summary.text
    body = summary.json()
    assert body["done"] is True and body["ended"] == 3
    runs = [client.get(f"/api/runs/{run_id}").json() for run_id in run_ids]
    for check in body["checks"]:
        per_case = [
            next(c["value"] for c in run["checks"] if c["name"] == check["name"]) for run in runs
        ]
        assert check["per_case"] == per_case
        finite = [v if v is not None else math.nan for v in per_case]
        if any(v is None for v in per_case):
            assert check["value"] is None and check["passed"] is False
        elif check["comparison"] == "<=":
            assert check["value"] == max(finite)
        else:
            assert check["value"] == min(finite)
        assert check["passed"] == (
            check["value"] is not None
            and (
                check["value"] <= check["threshold"]
                if check["comparison"] == "<="
                else check["value"] >= check["threshold"]
            )
        )
    every_finished = all(run["state"] == "finished" for run in runs)
    assert body["passed"] == (every_finished and all(c["passed"] for c in body["checks"]))


def test_wrong_cases_are_refused_with_a_sentence(lab) -> None:
    client = lab.student("case-refusals")
    nodes = starter_nodes(client)
    answer = start_case(client, nodes, 3)
    assert answer.status_code == 422 and "3 grading cases (0 to 2)" in answer.text
    answer = start_case(client, nodes, 1, seed=5)
    assert answer.status_code == 422 and "a case or a seed, not both" in answer.text
    answer = client.post(
        "/api/runs",
        json={"robot": "crowbot", "world": "wall_approach", "nodes": nodes, "case": 0},
    )
    assert answer.status_code == 422 and "name the exercise" in answer.text


def test_the_summary_reads_only_the_callers_runs_of_that_exercise(lab) -> None:
    owner = lab.student("check-owner")
    other = lab.student("check-other")
    run_id = start_case(owner, starter_nodes(owner), 0, duration=1.0).json()["id"]
    wait_for_end(owner, run_id, timeout_s=120)

    assert other.get(f"/api/exercises/{EXERCISE}/check", params={"runs": run_id}).status_code == 404
    wrong = owner.get("/api/exercises/ir_scout_avoidance/check", params={"runs": run_id})
    assert wrong.status_code == 422 and "not a run of 'ir_scout_avoidance'" in wrong.text
    twice = owner.get(f"/api/exercises/{EXERCISE}/check", params={"runs": f"{run_id},{run_id}"})
    assert twice.status_code == 422 and "appears twice" in twice.text
    many = owner.get(f"/api/exercises/{EXERCISE}/check", params={"runs": "a,b,c,d"})
    assert many.status_code == 422 and "1 to 3 run ids" in many.text
    missing = owner.get(f"/api/exercises/{EXERCISE}/check", params={"runs": "nope"})
    assert missing.status_code == 404
