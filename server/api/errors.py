"""Every error a client can cause becomes a JSON answer with a sentence in `detail` that says
what is wrong and what to do. 422 lists the offending fields by path ("body.nodes.0.code");
404 for an unknown id lists the valid ones; 429 says when to retry. A fault of ours is logged
with an id and answered 500 with that id, never with a traceback."""

from __future__ import annotations

import logging
import uuid

from fastapi import FastAPI, Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse
from sqlalchemy.exc import DataError
from starlette.exceptions import HTTPException as StarletteHTTPException

from server.api import declared_errors
from server.runs.spec import RunSpecError
from server.service.catalog import UnknownIdError
from server.service.disk import DiskBudgetError
from server.service.exercises import ExerciseDefinitionError
from server.service.runs import RunLimitError, RunRequestError
from server.service.workspace_files import WorkspaceFileError
from server.workers.remote_bench import BenchUnavailableError

log = logging.getLogger("robodojo.api")


def _field_path(location: tuple) -> str:
    return ".".join(str(part) for part in location)


async def _validation(_: Request, error: RequestValidationError) -> JSONResponse:
    problems = []
    for item in error.errors():
        problems.append(
            {"field": _field_path(item.get("loc", ())), "message": str(item.get("msg", ""))}
        )
    first = problems[0] if problems else {"field": "request", "message": "invalid"}
    more = f" (and {len(problems) - 1} more problem(s))" if len(problems) > 1 else ""
    return JSONResponse(
        status_code=422,
        content={"detail": f"{first['field']}: {first['message']}{more}", "errors": problems},
    )


async def _http(_: Request, error: StarletteHTTPException) -> JSONResponse:
    return JSONResponse(
        status_code=error.status_code,
        content={"detail": error.detail},
        headers=getattr(error, "headers", None),
    )


async def _unknown_id(_: Request, error: UnknownIdError) -> JSONResponse:
    return JSONResponse(status_code=404, content={"detail": str(error), "valid": error.valid})


async def _run_limit(_: Request, error: RunLimitError) -> JSONResponse:
    return JSONResponse(
        status_code=429,
        content={"detail": str(error), "retry_after_s": error.retry_after_s},
        headers={"Retry-After": str(error.retry_after_s)},
    )


async def _bench_away(_: Request, error: BenchUnavailableError) -> JSONResponse:
    # 503: the robots' bench worker (or Redis) is away; trying again later may work.
    headers = {"Retry-After": "5"}
    return JSONResponse(status_code=503, content={"detail": str(error)}, headers=headers)


async def _disk_budget(_: Request, error: DiskBudgetError) -> JSONResponse:
    # 507 Insufficient Storage (RFC 4918 11.5): waiting does not help, freeing space does.
    return JSONResponse(status_code=507, content={"detail": str(error)})


async def _bad_run(_: Request, error: Exception) -> JSONResponse:
    return JSONResponse(status_code=422, content={"detail": str(error)})


async def _bad_file(_: Request, error: WorkspaceFileError) -> JSONResponse:
    return JSONResponse(status_code=error.status, content={"detail": str(error)})


async def _broken_exercise(_: Request, error: Exception) -> JSONResponse:
    return JSONResponse(
        status_code=409,
        content={"detail": f"this exercise cannot be used as stored: {error}. An instructor "
                 "can fix it (PUT /api/admin/exercises/{id})."},
    )  # fmt: skip


async def _data_error(_: Request, error: DataError) -> JSONResponse:
    # PostgreSQL refuses some values SQLite takes (a NUL character in text, say): those come
    # from what the client sent, so they are the client's to change, not a fault of ours.
    log.info("refused by the database: %s", error.orig)
    return JSONResponse(
        status_code=422,
        content={"detail": "the request holds a value the database cannot store (a NUL "
                 "character in text, or a number out of range); remove it and try again"},
    )  # fmt: skip


async def _internal(request: Request, error: Exception) -> JSONResponse:
    incident = uuid.uuid4().hex[:8]
    log.exception("incident %s: %s %s failed", incident, request.method, request.url.path)
    return JSONResponse(
        status_code=500,
        content={
            "detail": f"the server hit a fault of its own (incident {incident}); it is logged. "
            "Try again; if it persists, tell your instructor the incident number."
        },
    )


# Our 422 as the OpenAPI describes it (FastAPI's default says `detail` is a list of pydantic's
# error objects, which we never send): a sentence, and for bad fields their paths and messages.
VALIDATION_ERROR_SCHEMA = {
    "title": "HTTPValidationError",
    "type": "object",
    "required": ["detail"],
    "properties": {
        "detail": {"type": "string", "title": "Detail", "description": "what is wrong"},
        "errors": {
            "type": "array",
            "title": "Errors",
            "items": {
                "type": "object",
                "required": ["field", "message"],
                "properties": {"field": {"type": "string"}, "message": {"type": "string"}},
            },
        },
    },
}


def _document(app: FastAPI) -> None:
    """Make /openapi.json say what `_validation` and `_bad_run` really answer with 422."""
    generate = app.openapi

    def openapi() -> dict:
        if app.openapi_schema is None:
            schema = generate()
            components = schema.get("components", {}).get("schemas", {})
            if "HTTPValidationError" in components:
                components["HTTPValidationError"] = VALIDATION_ERROR_SCHEMA
            components.pop("ValidationError", None)
            declared_errors.declare(app, schema)  # every status each operation can answer
            app.openapi_schema = schema
        return app.openapi_schema

    app.openapi = openapi  # type: ignore[method-assign]


def install(app: FastAPI) -> None:
    _document(app)
    app.add_exception_handler(RequestValidationError, _validation)
    app.add_exception_handler(StarletteHTTPException, _http)
    app.add_exception_handler(UnknownIdError, _unknown_id)
    app.add_exception_handler(RunLimitError, _run_limit)
    app.add_exception_handler(DiskBudgetError, _disk_budget)
    app.add_exception_handler(BenchUnavailableError, _bench_away)
    app.add_exception_handler(RunRequestError, _bad_run)
    app.add_exception_handler(RunSpecError, _bad_run)
    app.add_exception_handler(WorkspaceFileError, _bad_file)
    app.add_exception_handler(ExerciseDefinitionError, _broken_exercise)
    app.add_exception_handler(DataError, _data_error)
    app.add_exception_handler(Exception, _internal)
