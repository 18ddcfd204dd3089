"""schemathesis (v4) against the real server's /openapi.json, as a student and as an instructor:
every operation gets generated requests (its examples, the coverage phase's boundary values and
hypothesis' fuzzing), and none may answer with a server error; answers whose status the schema
declares must match its body schema and content type.

The server is `robodojo serve` on a temporary SQLite with the real sandbox (tests/api/conftest.py
starts it), its runs capped at a few seconds of robot time so generated `POST /api/runs` end
quickly. Issue 14's sweep sent 12,196 such requests to a running lab; this keeps a bounded share
of that in CI (max_examples below, ~1-2 min on a 2-core machine).

Every status an answer has must be one its operation declares (`status_code_conformance`,
issue 33): server/api/declared_errors.py adds the errors FastAPI's generated schema cannot see
(the guards' 400/408/413, login's 401, CSRF's 403, the service's 409/429/503/507). Left out: the
websockets (`/api/runs/{id}/live`, the 3D view) are not in the OpenAPI (schemathesis speaks HTTP
only; tests/api/test_live.py drives them).
"""

from __future__ import annotations

import time
from collections.abc import Iterator

import httpx
import pytest
import schemathesis
from hypothesis import HealthCheck, settings
from hypothesis import strategies as st
from schemathesis.checks import not_a_server_error
from schemathesis.specs.openapi.checks import (
    content_type_conformance,
    response_schema_conformance,
    status_code_conformance,
)

from tests.api.conftest import (
    STEP_CONTROLLER,
    LabServer,
    start_server,
    stop_server,
    wait_for_end,
)

pytestmark = pytest.mark.slow  # generated requests by the thousand: minutes

MAX_EXAMPLES = 8  # generated requests per operation and role, besides examples and coverage
ROLES = ("student", "instructor")
RUN_CAP_S = 3  # [s] of robot time: the longest run a generated request may start
LAB_ROOM_WAIT_S = 120.0  # [s] the fuzzing's last runs finish well within this, even under load
# A run that starts and ends within a second of robot time: half the stateful phase's
# `POST /api/runs` send it (generated bodies almost never pass the run validators), so the
# links from a started run to its logs, CSV files, recording and artifacts have a real run.
SHORT_RUN = {
    "robot": "crowbot",
    "world": "wall_approach",
    "nodes": [{"name": "driver", "code": STEP_CONTROLLER}],
    "clock": "lockstep",
    "duration": 1,
}
STATEFUL_SCENARIOS = 10  # chains of linked requests per role, up to 6 steps each


@pytest.fixture(scope="module")
def fuzz_lab(tmp_path_factory) -> Iterator[LabServer]:
    server = start_server(
        tmp_path_factory.mktemp("lab-fuzz"),
        {"ROBODOJO_MAX_RUN_DURATION_S": str(RUN_CAP_S), "ROBODOJO_MAX_RUNS_TOTAL": "4"},
    )
    assert server.admin_token, "the server printed no login URL:\n" + "\n".join(server.output)
    yield server
    stop_server(server)


@pytest.fixture(scope="module")
def bearers(fuzz_lab: LabServer) -> dict[str, str]:
    """A token per role, each a fresh user with its own workspaces and runs."""
    return {role: fuzz_lab.new_user(f"fuzz-{role}", role=role)[1] for role in ROLES}


@pytest.fixture(scope="module")
def api_schema(fuzz_lab: LabServer):
    return schemathesis.openapi.from_url(f"{fuzz_lab.url}/openapi.json")


CHECKS = [
    not_a_server_error,
    status_code_conformance,
    response_schema_conformance,
    content_type_conformance,
]
schema = schemathesis.pytest.from_fixture("api_schema")


@schema.parametrize()
@settings(
    max_examples=MAX_EXAMPLES,
    deadline=None,
    suppress_health_check=list(HealthCheck),
    derandomize=True,  # the same requests every CI run: a failure here is reproducible
)
def test_no_server_error(case, bearers: dict[str, str], fuzz_lab: LabServer) -> None:
    """Each generated request is sent twice: as the student, then as the instructor."""
    for role in ROLES:
        response = case.call(headers={"Authorization": f"Bearer {bearers[role]}"}, timeout=30)
        assert response.status_code < 500, (
            f"as the {role}: {case.method} {case.formatted_path} answered "
            f"{response.status_code}:\n{response.text[:2000]}\n--- server output ---\n"
            + "\n".join(fuzz_lab.output[-40:])
        )
        case.validate_response(response, checks=CHECKS)


@pytest.fixture(scope="module")
def linked_schema(fuzz_lab: LabServer):
    """Its own copy of the schema: the hook below must not narrow the per-operation fuzzing."""
    # Only the chains the issue names (users, runs and their files, workspaces): with every
    # operation in, a few scenarios rarely pick a link's second step.
    linked = schemathesis.openapi.from_url(f"{fuzz_lab.url}/openapi.json").include(
        path_regex=r"^/api/(runs|admin/users|workspaces)"
    )

    @linked.hook
    def flatmap_body(context, body):
        operation = context.operation
        if operation is not None and (operation.method.upper(), operation.path) == (
            "POST",
            "/api/runs",
        ):
            return st.sampled_from([body, SHORT_RUN])
        return st.just(body)

    return linked


@pytest.mark.parametrize("role", ROLES)
def test_stateful_links(role: str, linked_schema, bearers: dict[str, str]) -> None:
    """schemathesis' stateful phase: it infers links from our schema (a created user's id to
    its token and disable routes, a started run's id to its logs, CSV files, recording and
    artifacts, a workspace to its files' versions) and walks chains of them, so the follow-up
    requests name things that exist instead of random ids."""
    headers = {"Authorization": f"Bearer {bearers[role]}"}

    class Workflow(linked_schema.as_state_machine()):
        def get_call_kwargs(self, case) -> dict:
            return {"headers": headers, "timeout": 30}

        def validate_response(self, response, case, additional_checks=None, **kwargs) -> None:
            case.validate_response(response, checks=CHECKS)

    Workflow.run(
        settings=settings(
            max_examples=STATEFUL_SCENARIOS,
            stateful_step_count=6,
            deadline=None,
            suppress_health_check=list(HealthCheck),
            derandomize=True,
        )
    )


def test_the_schema_describes_our_422(fuzz_lab: LabServer) -> None:
    """The fuzzing found /openapi.json promising FastAPI's 422 (`detail` a list of pydantic's
    error objects) while every 422 we send has a sentence in `detail` and the fields in
    `errors`: the schema now says so, checked here against a real 422."""
    with fuzz_lab.admin() as admin:
        declared = admin.get("/openapi.json").json()["components"]["schemas"]
        answer = admin.post("/api/admin/users", json={"name": ""})
    assert answer.status_code == 422, answer.text
    schema = declared["HTTPValidationError"]
    assert schema["properties"]["detail"]["type"] == "string"
    body = answer.json()
    assert isinstance(body["detail"], str) and "body.name" in body["detail"]
    assert set(body) <= set(schema["properties"])
    assert body["errors"][0].keys() == schema["properties"]["errors"]["items"]["properties"].keys()


def start_when_the_lab_has_room(client: httpx.Client) -> httpx.Response:
    """POST a short run, waiting as its 429 says while the fuzzing's own runs (at most 4 at
    once on this server) are still finishing: on a loaded machine they outlast the fuzz."""
    deadline = time.monotonic() + LAB_ROOM_WAIT_S
    while True:
        answer = client.post("/api/runs", json=SHORT_RUN)
        if answer.status_code != 429 or time.monotonic() > deadline:
            return answer
        time.sleep(min(float(answer.json().get("retry_after_s", 1)), 2.0))


def test_run_files_answer_with_the_content_types_the_schema_declares(
    fuzz_lab: LabServer,
) -> None:
    """The stateful phase found the recording declared as JSON while it is sent as bytes; the
    file routes now declare their real types, and a started run's links name its `id`."""
    student = fuzz_lab.student("fuzz-files")
    spec = student.get("/openapi.json").json()
    started = start_when_the_lab_has_room(student)
    assert started.status_code == 201, started.text
    run = wait_for_end(student, started.json()["id"])
    assert run["state"] == "finished", run
    links = spec["paths"]["/api/runs"]["post"]["responses"]["201"]["links"]
    assert links["get_logs"]["parameters"] == {"run_id": "$response.body#/id"}
    csv_name = student.get(f"/api/runs/{run['id']}/csv").json()["files"][0]["name"]
    for path, template in [
        (f"/api/runs/{run['id']}/recording.mcap", "/api/runs/{run_id}/recording.mcap"),
        (f"/api/runs/{run['id']}/csv/{csv_name}", "/api/runs/{run_id}/csv/{name}"),
        (f"/api/runs/{run['id']}/logs/driver.log", "/api/runs/{run_id}/logs/{node}.log"),
    ]:
        answer = student.get(path)
        assert answer.status_code == 200, (path, answer.text)
        declared = spec["paths"][template]["get"]["responses"]["200"]["content"]
        sent = answer.headers["content-type"].split(";")[0]
        assert sent in declared, (path, sent, declared)
