"""The editor's help while a student types: diagnostics, completion with signature help, hover
and formatting (server/editor). The robot whose topics the analysis knows comes from the
exercise (or the free-play workspace's robot, or `robot`). Nothing here runs the student's
code: it is read by ruff and jedi as text, inside the editor's sandbox (docs/architecture.md,
"Editor"). Each student has one request analysed at a time behind a bounded queue: past it,
429 with a sentence."""

from __future__ import annotations

from fastapi import APIRouter, Depends, HTTPException, Request
from pydantic import Field

from server.api.auth import Caller, current_user
from server.api.schemas import HARD_CODE_CAP, Strict
from server.editor.context import RunContext, builtin_topics
from server.editor.ruff_tool import FormatError, RuffUnavailable
from server.editor.service import CodeTooLarge, EditorBusy, EditorService, InvalidText
from server.service import catalog, exercises
from server.sim import robot_ids

router = APIRouter(prefix="/api/editor", tags=["editor"])
MAX_LINE = 10_000_000  # a bound far past any file the size limit lets through


class EditorText(Strict):
    code: str = Field(max_length=HARD_CODE_CAP, description="the file's text, as in the editor")
    filename: str = Field("controller.py", max_length=200, description="for messages only")


class AnalysedText(EditorText):
    exercise: str | None = Field(None, max_length=64, description="exercise (or robot) id")
    robot: str | None = Field(None, max_length=64, description="robot id; wins over exercise")


class Position(AnalysedText):
    line: int = Field(ge=1, le=MAX_LINE, description="1-based line of the cursor")
    column: int = Field(ge=0, le=MAX_LINE, description="0-based column of the cursor")


def _service(request: Request) -> EditorService:
    return request.app.state.editor


def _context(request: Request, body: AnalysedText) -> RunContext:
    """The robot, and the topics of the exercise's built-in nodes, that the analysis knows;
    404 for an unknown id. A free-play workspace is named after its robot."""
    if body.robot is not None:
        catalog.check_robot(body.robot)
    if body.exercise is None or body.exercise in robot_ids():
        return RunContext(body.robot or body.exercise)
    with request.app.state.store.session() as db:
        exercise = exercises.find(db, body.exercise).exercise
    if body.robot not in (None, exercise.robot):  # another robot than the exercise's
        return RunContext(body.robot)
    return RunContext(exercise.robot, builtin_topics(exercise.builtin_nodes))


def _refused(error: Exception) -> HTTPException:
    """The HTTP answer to a refusal every route shares."""
    if isinstance(error, CodeTooLarge):
        return HTTPException(413, str(error))
    if isinstance(error, EditorBusy):
        return HTTPException(429, str(error))
    return HTTPException(422, str(error))  # InvalidText


REFUSALS = (CodeTooLarge, EditorBusy, InvalidText)


@router.post("/lint", summary="Diagnostics: ruff's (pyflakes, syntax) and RoboDojo's API checks")
def lint(body: AnalysedText, request: Request, caller: Caller = Depends(current_user)) -> dict:
    try:
        context = _context(request, body)
        return {"diagnostics": _service(request).lint(body.code, context, caller.id)}
    except REFUSALS as error:
        raise _refused(error) from None


@router.post("/complete", summary="Completions and signature help at the cursor")
def complete(body: Position, request: Request, caller: Caller = Depends(current_user)) -> dict:
    try:
        return _service(request).complete(
            body.code, body.line, body.column, _context(request, body), caller.id
        )
    except REFUSALS as error:
        raise _refused(error) from None


@router.post("/hover", summary="What the name at the cursor is: a field's type and unit")
def hover(body: Position, request: Request, caller: Caller = Depends(current_user)) -> dict:
    try:
        return _service(request).hover(
            body.code, body.line, body.column, _context(request, body), caller.id
        )
    except REFUSALS as error:
        raise _refused(error) from None


@router.post("/format", summary="The text as ruff format writes it")
def format_code(body: EditorText, request: Request, caller: Caller = Depends(current_user)) -> dict:
    try:
        return {"code": _service(request).format(body.code, caller.id)}
    except REFUSALS as error:
        raise _refused(error) from None
    except FormatError as error:
        raise HTTPException(422, str(error)) from None
    except RuffUnavailable as error:
        raise HTTPException(503, str(error)) from None  # the sentence says when to ask again
