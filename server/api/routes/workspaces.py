"""Students' code: a workspace per exercise (or per robot, for free play), one file per node,
every save kept as a version. Only the owner sees a workspace; an empty one starts from the
exercise's starter code."""

from __future__ import annotations

from fastapi import APIRouter, Depends, HTTPException, Path, Request

from server.api.auth import Caller, current_user
from server.api.routes.runs import iso
from server.api.schemas import CodeSave
from server.service import exercises
from server.service.catalog import UnknownIdError
from server.sim import robot_ids
from server.store import workspaces as store
from server.store.models import CodeVersion

router = APIRouter(prefix="/api/workspaces", tags=["workspaces"])
FILE_PATTERN = r"^[A-Za-z][A-Za-z0-9_]{0,39}(\.py)?$"
FileName = Path(pattern=FILE_PATTERN, description="node file: a node name, optionally .py")
WorkspaceId = Path(max_length=64)
VersionNumber = Path(ge=1, le=2**31 - 1, description="a version number, from 1")


def _starter(request: Request, workspace: str) -> list[tuple[str, str]]:
    """(file name, code) to start from; raises 404 for a workspace that names nothing."""
    if workspace in robot_ids():
        return []
    with request.app.state.store.session() as db:
        try:
            entry = exercises.find(db, workspace)
        except UnknownIdError as error:
            raise UnknownIdError(
                "workspace (an exercise or robot)", workspace, [*error.valid, *robot_ids()]
            ) from None
    return [(f"{name}.py", code) for name, _, code in entry.starter]


def _version_out(version: CodeVersion, with_code: bool = True) -> dict:
    out = {
        "filename": version.filename,
        "version": version.version,
        "saved_at": iso(version.created_at),
        "bytes": len(version.code.encode()),
    }
    if with_code:
        out["code"] = version.code
    return out


def _filename(name: str) -> str:
    return name if name.endswith(".py") else f"{name}.py"


@router.get("/{workspace}", summary="My files in a workspace (newest versions)")
def get_workspace(
    request: Request, workspace: str = WorkspaceId, caller: Caller = Depends(current_user)
) -> dict:
    starter = _starter(request, workspace)
    with request.app.state.store.session() as db:
        files = [_version_out(v) for v in store.latest_files(db, caller.id, workspace)]
    saved = {f["filename"] for f in files}
    # Starter files not saved yet (version 0), so a four-node exercise keeps its four files.
    files += [
        {"filename": name, "version": 0, "saved_at": None, "bytes": len(code), "code": code}
        for name, code in starter
        if name not in saved
    ]
    return {"workspace": workspace, "files": sorted(files, key=lambda f: f["filename"])}


@router.delete("/{workspace}/files/{filename}", summary="Delete a file and its versions")
def delete_file(
    request: Request,
    workspace: str = WorkspaceId,
    filename: str = FileName,
    caller: Caller = Depends(current_user),
) -> dict:
    with request.app.state.store.session() as db:
        removed = store.delete_file(db, caller.id, workspace, _filename(filename))
    if not removed:
        raise HTTPException(404, f"no saved file '{filename}' in '{workspace}'")
    return {"ok": True, "versions_removed": removed}


@router.put("/{workspace}/files/{filename}", summary="Save a file (a new version)")
def save_file(
    body: CodeSave,
    request: Request,
    workspace: str = WorkspaceId,
    filename: str = FileName,
    caller: Caller = Depends(current_user),
) -> dict:
    _starter(request, workspace)
    settings = request.app.state.settings
    size = len(body.code.encode())
    if size > settings.max_code_bytes_per_file:
        raise HTTPException(
            413, f"the file has {size} bytes; the limit is {settings.max_code_bytes_per_file}"
        )
    name = _filename(filename)
    with request.app.state.store.session() as db:
        names = {v.filename for v in store.latest_files(db, caller.id, workspace)}
        if name not in names and len(names) >= settings.max_files_per_workspace:
            raise HTTPException(
                422, f"a workspace holds at most {settings.max_files_per_workspace} files"
            )
        return _version_out(store.save(db, caller.id, workspace, name, body.code), False)


@router.get("/{workspace}/files/{filename}/versions", summary="A file's saved versions")
def list_versions(
    request: Request,
    workspace: str = WorkspaceId,
    filename: str = FileName,
    caller: Caller = Depends(current_user),
) -> dict:
    with request.app.state.store.session() as db:
        found = store.versions(db, caller.id, workspace, _filename(filename))
    if not found:
        raise HTTPException(404, f"no saved versions of '{filename}' in '{workspace}'")
    return {"versions": [_version_out(v, False) for v in found]}


def _one_version(request: Request, caller: Caller, workspace: str, filename: str, number: int):
    with request.app.state.store.session() as db:
        version = store.get_version(db, caller.id, workspace, _filename(filename), number)
    if version is None:
        raise HTTPException(404, f"no version {number} of '{filename}' in '{workspace}'")
    return version


@router.get("/{workspace}/files/{filename}/versions/{number}", summary="One saved version")
def get_version(
    request: Request,
    number: int = VersionNumber,
    workspace: str = WorkspaceId,
    filename: str = FileName,
    caller: Caller = Depends(current_user),
) -> dict:
    return _version_out(_one_version(request, caller, workspace, filename, number))


@router.post(
    "/{workspace}/files/{filename}/versions/{number}/restore",
    summary="Make an old version the newest again (saved as a new version)",
)
def restore_version(
    request: Request,
    number: int = VersionNumber,
    workspace: str = WorkspaceId,
    filename: str = FileName,
    caller: Caller = Depends(current_user),
) -> dict:
    old = _one_version(request, caller, workspace, filename, number)
    with request.app.state.store.session() as db:
        return _version_out(store.save(db, caller.id, workspace, old.filename, old.code))
