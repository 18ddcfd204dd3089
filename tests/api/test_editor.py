"""The editor's routes through the real server (server/api/routes/editor.py): diagnostics,
completion, hover and formatting as the browser asks for them, logged in and from our own
origin only, and hostile text answered with sentences, never a 500 or a hang."""

from __future__ import annotations

import pytest

from tests.editor.hostile_texts import DEEPLY_NESTED
from tests.waiting import wait_until

READY_S = 180.0  # [s] the analysis workers' start and warm-up on a loaded 2-core machine
TYPO = "from geometry_msgs.msg import Twist\ncmd = Twist()\ncmd.linear_x = 0.1\nprint(distancia)\n"


def body(code: str, **more) -> dict:
    return {"code": code, "filename": "driver.py", "exercise": None, "robot": None, **more}


def at_end(code: str, **more) -> dict:
    lines = code.split("\n")
    return body(code, line=len(lines), column=len(lines[-1]), **more)


@pytest.fixture
def student(lab):
    """A logged-in student, once the server's analysis workers answer."""
    client = lab.student()

    def ready():
        answer = client.post("/api/editor/complete", json=at_end("import rospy\nrospy."))
        return answer.status_code == 200 and answer.json()["completions"]

    wait_until(ready, READY_S, "the editor's analysis answered", poll_s=0.5)
    return client


def test_lint_underlines_a_typo_with_its_rule_and_sentence(student):
    answer = student.post("/api/editor/lint", json=body(TYPO))
    assert answer.status_code == 200, answer.text
    found = answer.json()["diagnostics"]
    assert [(d["line"], d["rule"], d["severity"]) for d in found] == [
        (3, "robodojo-field", "error"),
        (4, "F821", "error"),
    ]
    assert found[0]["message"].startswith("`Twist` has no field `linear_x`.")
    assert (found[0]["column"], found[0]["end_line"], found[0]["end_column"]) == (4, 3, 12)
    assert found[1]["message"] == "Undefined name `distancia`."


def test_lint_knows_the_exercises_robot(student):
    code = 'SUBSCRIBE = ["Distanse"]\n\ndef step(obs):\n    return None\n'
    found = student.post(
        "/api/editor/lint", json=body(code, exercise="crowbot_distance_pid")
    ).json()["diagnostics"]
    assert [d["rule"] for d in found] == ["robodojo-topic"]
    assert "Did you mean `Distance`?" in found[0]["message"]
    # A free-play workspace is named after its robot; another robot has other topics.
    same = student.post("/api/editor/lint", json=body(code, exercise="crowbot")).json()
    assert same["diagnostics"] == found
    other = student.post("/api/editor/lint", json=body(code, robot="turtlebot3")).json()
    assert "robot turtlebot3" in other["diagnostics"][0]["message"]


def test_a_syntax_error_gives_diagnostics_not_an_error(student):
    answer = student.post("/api/editor/lint", json=body("def broken(:\n    pass\n"))
    assert answer.status_code == 200
    assert answer.json()["diagnostics"][0]["rule"] == "E999"


def test_completion_offers_linear_after_cmd(student):
    code = "from geometry_msgs.msg import Twist\ncmd = Twist()\ncmd."
    answer = student.post("/api/editor/complete", json=at_end(code))
    assert answer.status_code == 200, answer.text
    completions = {c["label"]: c for c in answer.json()["completions"]}
    assert completions["linear"] == {
        "label": "linear",
        "type": "property",
        "detail": "linear: geometry_msgs/Vector3 [m/s]",
        "doc": "linear: geometry_msgs/Vector3 [m/s]",
    }
    assert answer.json()["signature"] is None


def test_completion_of_obs_and_signature_help(student):
    code = "def step(obs):\n    obs."
    answer = student.post(
        "/api/editor/complete", json=at_end(code, exercise="crowbot_distance_pid")
    )
    assert {"Distance", "Button", "time"} <= {c["label"] for c in answer.json()["completions"]}
    code = "import rospy\nrospy.Subscriber('Distance', "
    signature = student.post("/api/editor/complete", json=at_end(code)).json()["signature"]
    assert signature["label"].startswith("Subscriber(") and signature["active"] == 1


def test_hover_gives_a_fields_type_and_unit(student):
    code = "from sensor_msgs.msg import LaserScan\nLaserScan().range_max\n"
    answer = student.post("/api/editor/hover", json=body(code, line=2, column=15))
    assert answer.status_code == 200
    assert answer.json() == {"text": "range_max: float32 [m]"}


def test_format_rewrites_and_refuses_a_syntax_error_with_its_line(student):
    answer = student.post(
        "/api/editor/format", json={"code": "if x :\n  y=1\n", "filename": "a.py"}
    )
    assert answer.status_code == 200 and answer.json() == {"code": "if x:\n    y = 1\n"}
    answer = student.post(
        "/api/editor/format", json={"code": "x = 1\ndef f(:\n", "filename": "a.py"}
    )
    assert answer.status_code == 422
    assert answer.json()["detail"].startswith("cannot format: line 2 ")


def test_routes_need_a_login(lab):
    anonymous = lab.client()
    for route, payload in (
        ("lint", body("x = 1\n")),
        ("complete", at_end("x")),
        ("hover", at_end("x")),
        ("format", {"code": "x = 1\n", "filename": "a.py"}),
    ):
        answer = anonymous.post(f"/api/editor/{route}", json=payload)
        assert answer.status_code == 401, (route, answer.text)
        assert "not logged in" in answer.json()["detail"]


def test_a_post_from_another_origin_is_refused(lab):
    client = lab.student()
    client.headers["Origin"] = "https://evil.example"
    answer = client.post("/api/editor/lint", json=body("x = 1\n"))
    assert answer.status_code == 403


def test_an_unknown_exercise_is_a_404_naming_the_valid_ones(lab):
    answer = lab.student().post("/api/editor/lint", json=body("x = 1\n", exercise="nope"))
    assert answer.status_code == 404
    assert "unknown exercise 'nope'" in answer.json()["detail"]


def test_a_file_over_the_labs_limit_is_refused_with_a_sentence(lab):
    client = lab.student()
    big = "x = 1\n" * 60_000  # 360 KiB: past the 256 KiB per-file limit, within the body limit
    for route, payload in (("lint", body(big)), ("complete", at_end(big)),
                           ("format", {"code": big, "filename": "a.py"})):  # fmt: skip
        answer = client.post(f"/api/editor/{route}", json=payload)
        assert answer.status_code == 413, (route, answer.text)
        assert "larger than the lab's limit of 256 KiB per file" in answer.json()["detail"]


def test_a_5_mb_file_is_refused_before_it_is_read(lab):
    answer = lab.student().post("/api/editor/lint", json=body("#" * 5_000_000))
    assert answer.status_code == 413
    assert answer.json()["detail"]  # a sentence, from the body limit


@pytest.mark.parametrize("code", DEEPLY_NESTED.values(), ids=DEEPLY_NESTED.keys())
def test_deeply_nested_code_is_answered_quickly(student, code):
    answer = student.post("/api/editor/lint", json=body(code))
    assert answer.status_code == 200
    assert "Python cannot compile code nested this deeply" in str(answer.json())
    answer = student.post("/api/editor/complete", json=at_end(code))
    assert answer.status_code == 200 and answer.json()["completions"] == []
    # ... and the editor still helps afterwards.
    after = student.post("/api/editor/complete", json=at_end("import rospy\nrospy."))
    assert after.json()["completions"]
