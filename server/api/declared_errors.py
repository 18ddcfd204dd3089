"""The error statuses each operation of /openapi.json declares, so a client (and schemathesis'
status check, tests/api/test_schemathesis.py) knows every answer it can get, not only 200.

FastAPI's generated schema lists a route's success and, where it has parameters, 422. Our
routes also answer from layers it cannot see: the guards before any route (a NUL in the
address 400, a body too large 413 or too slow 408), login (401), the CSRF guard on a cookie's
state change (403), the admin routes' 404 to a student, and the errors the service raises
(errors.py maps each to its status). Those are declared here by rule, each with the sentence a
reader of /docs sees, and what no rule can know is the table `RAISED` below, by operation.
Every error body is `{"detail": "<a sentence>"}`, sometimes with more fields beside it.
"""

from __future__ import annotations

from collections.abc import Iterator

from fastapi import FastAPI
from fastapi.dependencies.models import Dependant
from fastapi.routing import APIRoute

from server.api.auth import current_user, instructor

ERROR_SCHEMA = {
    "title": "Error",
    "type": "object",
    "required": ["detail"],
    "properties": {"detail": {"type": "string", "description": "what is wrong and what to do"}},
    "additionalProperties": True,
}

MEANING = {
    400: "the address holds a NUL character",
    401: "not logged in: no session cookie or bearer token, or one that ended",
    403: "a cookie-authenticated change from a page of another origin (CSRF)",
    404: "no such thing, or it is not yours (admin routes: not an instructor)",
    408: "the request body did not arrive in time",
    409: "the request conflicts with the current state (the sentence says which)",
    410: "the run's files were removed by the lab's retention",
    413: "the request body is larger than the lab accepts",
    422: "a value in the request is not valid (the sentence names it)",
    429: "a limit was reached: wait as Retry-After says and try again",
    503: "a part of the lab the request needs is busy or away (the sentence says which)",
    507: "a disk budget is full",
}

UNSAFE_METHODS = {"POST", "PUT", "PATCH", "DELETE"}

# What the service layer or the route itself raises, beyond the rules: (method, path) -> codes.
RAISED: dict[tuple[str, str], tuple[int, ...]] = {
    ("POST", "/api/runs"): (409, 429, 503, 507),
    ("POST", "/api/runs/{run_id}/stop"): (409,),
    ("POST", "/api/runs/{run_id}/estop"): (409,),
    ("POST", "/api/runs/{run_id}/pause"): (409,),
    ("POST", "/api/runs/{run_id}/resume"): (409,),
    ("GET", "/api/runs/{run_id}/recording.mcap"): (409, 410),
    ("GET", "/api/runs/{run_id}/csv"): (409, 410),
    ("GET", "/api/runs/{run_id}/csv/{name}"): (409, 410),
    ("GET", "/api/runs/{run_id}/logs"): (410,),
    ("GET", "/api/runs/{run_id}/logs/{node}.log"): (410,),
    ("GET", "/api/runs/{run_id}/artifacts"): (410,),
    ("GET", "/api/runs/{run_id}/artifacts/{name:path}"): (410,),
    ("GET", "/api/runs/{run_id}/viz"): (409,),
    ("GET", "/api/runs/{run_id}/viz/{asset:path}"): (409,),
    ("GET", "/api/exercises/{exercise_id}/check"): (409, 429, 503, 507),
    ("PUT", "/api/workspaces/{workspace}/files/{filename:path}"): (409,),
    ("POST", "/api/admin/users"): (409,),
    ("POST", "/api/admin/users/bulk"): (409,),
    ("PATCH", "/api/admin/users/{user_id}"): (409,),
    ("POST", "/api/admin/users/{user_id}/disable"): (409,),
    ("POST", "/api/admin/runs/{run_id}/stop"): (409,),
    ("POST", "/api/admin/courses"): (409,),
    ("PUT", "/api/admin/courses/{course_id}/students/{user_id}"): (409,),
    ("PUT", "/api/admin/courses/{course_id}/exercises/{exercise_id}"): (409,),
    ("POST", "/api/admin/exercises"): (409,),
    ("PUT", "/api/admin/exercises/{exercise_id}"): (409,),
    ("DELETE", "/api/admin/exercises/{exercise_id}"): (409,),
    ("POST", "/api/admin/exercises/{exercise_id}/try"): (409, 429, 503, 507),
    ("POST", "/api/admin/robots"): (409,),
    ("PATCH", "/api/admin/robots/{name}"): (409,),
    ("DELETE", "/api/admin/robots/{name}"): (409,),
    ("POST", "/api/hardware/{name}/queue"): (409,),
    ("DELETE", "/api/hardware/{name}/queue"): (409,),
    ("POST", "/api/admin/hardware/{name}/queue/move"): (409,),
    ("POST", "/api/admin/hardware/{name}/queue/skip"): (409,),
    ("GET", "/api/courses/{course_id}/leaderboards/{exercise_id}"): (409,),
    ("POST", "/api/editor/lint"): (413, 429, 503),
    ("POST", "/api/editor/complete"): (413, 429, 503),
    ("POST", "/api/editor/hover"): (413, 429, 503),
    ("POST", "/api/editor/format"): (413, 429, 503),
    ("POST", "/login"): (401, 403),
    ("GET", "/login"): (401,),
    ("POST", "/api/session"): (401, 403),
}


def _depends_on(dependant: Dependant, wanted) -> bool:
    return any(sub.call is wanted or _depends_on(sub, wanted) for sub in dependant.dependencies)


def codes_for(route: APIRoute, method: str) -> set[int]:
    """Every error status `method` on `route` can answer with."""
    codes = {400, 408, 413}
    authenticated = _depends_on(route.dependant, current_user)
    if authenticated:
        codes.add(401)
        if method in UNSAFE_METHODS:
            codes.add(403)
    # An id in the path or the body (an exercise, robot or world named in a run or an editor
    # request) that names nothing: UnknownIdError's 404, with the valid ids.
    if (
        _depends_on(route.dependant, instructor)
        or route.dependant.path_params
        or route.dependant.body_params
    ):
        codes.add(404)
    if route.dependant.path_params or route.dependant.query_params or route.dependant.body_params:
        codes.add(422)
    codes.update(RAISED.get((method, route.path_format), ()))
    return codes


def _routes(items) -> Iterator[APIRoute]:
    """Every APIRoute, through included routers (ours add no prefix when included, so a route's
    own path is its full path)."""
    for route in items:
        if isinstance(route, APIRoute):
            yield route
        elif hasattr(route, "original_router"):  # FastAPI's included router
            yield from _routes(route.original_router.routes)


def declare(app: FastAPI, schema: dict) -> None:
    """Add every operation's error statuses to `schema` (the generated /openapi.json), each
    pointing at one `Error` body; a status the route already declares keeps its own body."""
    schema.setdefault("components", {}).setdefault("schemas", {})["Error"] = ERROR_SCHEMA
    for route in _routes(app.routes):
        if not route.include_in_schema:
            continue
        operations = schema.get("paths", {}).get(route.path_format, {})
        for method in route.methods:
            operation = operations.get(method.lower())
            if operation is None:
                continue
            responses = operation.setdefault("responses", {})
            for code in sorted(codes_for(route, method)):
                responses.setdefault(
                    str(code),
                    {
                        "description": MEANING[code],
                        "content": {
                            "application/json": {"schema": {"$ref": "#/components/schemas/Error"}}
                        },
                    },
                )
