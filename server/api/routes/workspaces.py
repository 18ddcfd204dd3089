"""Students' code: a workspace per exercise (or per robot, for free play), one file per node and
the data files next to them (CSV, YAML, JSON, TXT, launch files: server/service/
workspace_files.py), every save kept as a version. Only the owner sees a workspace; an empty one
starts from the exercise's starter code."""

from __future__ import annotations

from fastapi import APIRouter, Depends, HTTPException, Path, Request

from server.api.auth import Caller, current_user
from server.api.routes.runs import iso
from server.api.schemas import CodeSave
from server.service import workspace_files, workspace_runs
from server.store import workspaces as store
from server.store.models import CodeVersion

router = APIRouter(prefix="/api/workspaces", tags=["workspaces"])
FileName = Path(
    max_length=200,
    description="a node name (pid, pid.py) or a data file's path (waypoints.csv, config/a.yaml)",
)
WorkspaceId = Path(max_length=64)
VersionNumber = Path(ge=1, le=2**31 - 1, description="a version number, from 1")


def _starter(request: Request, workspace: str) -> list[tuple[str, str]]:
    """(file name, code) to start from; raises 404 for a workspace that names nothing."""
    with request.app.state.store.session() as db:
        return workspace_runs.starter_files(db, workspace)


def _version_out(version: CodeVersion, with_code: bool = True) -> dict:
    out = {
        "filename": version.filename,
        "version": version.version,
        "saved_at": iso(version.created_at),
        "bytes": len(version.code.encode()),
        "kind": "code" if workspace_files.is_code(version.filename) else "data",
    }
    if with_code:
        out["code"] = version.code
    return out


def _filename(name: str) -> str:
    return workspace_files.file_name(name)  # WorkspaceFileError: a 4xx with its sentence


def history_caps(settings) -> store.HistoryCaps:
    return store.HistoryCaps(
        versions_per_file=settings.max_versions_per_file,
        workspace_bytes=settings.max_history_bytes_per_workspace,
    )


def caps(settings) -> workspace_files.Caps:
    return workspace_files.Caps(
        code_bytes=settings.max_code_bytes_per_file,
        data_bytes=settings.max_data_bytes_per_file,
        workspace_bytes=settings.max_workspace_bytes,
        files=settings.max_files_per_workspace,
    )


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
        {
            "filename": name,
            "version": 0,
            "saved_at": None,
            "bytes": len(code),
            "kind": "code",
            "code": code,
        }
        for name, code in starter
        if name not in saved
    ]
    return {"workspace": workspace, "files": sorted(files, key=lambda f: f["filename"])}


@router.delete("/{workspace}/files/{filename:path}", summary="Delete a file and its versions")
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


@router.put("/{workspace}/files/{filename:path}", summary="Save a file (a new version)")
def save_file(
    body: CodeSave,
    request: Request,
    workspace: str = WorkspaceId,
    filename: str = FileName,
    caller: Caller = Depends(current_user),
) -> dict:
    _starter(request, workspace)
    name = _filename(filename)
    limits = caps(request.app.state.settings)
    workspace_files.check_content(name, body.code, limits)
    with request.app.state.store.session() as db:
        sizes = {
            v.filename: len(v.code.encode()) for v in store.latest_files(db, caller.id, workspace)
        }
        workspace_files.check_fits(name, body.code, sizes, limits)
        history = history_caps(request.app.state.settings)
        return _version_out(store.save(db, caller.id, workspace, name, body.code, history), False)


@router.get("/{workspace}/files/{filename:path}/versions", summary="A file's saved versions")
def list_versions(
    request: Request,
    workspace: str = WorkspaceId,
    filename: str = FileName,
    caller: Caller = Depends(current_user),
) -> dict:
    name = _filename(filename)
    with request.app.state.store.session() as db:
        found = store.versions(db, caller.id, workspace, name)
        oldest = store.oldest_kept(db, caller.id, workspace, name)
    if not found:
        raise HTTPException(404, f"no saved versions of '{filename}' in '{workspace}'")
    history = history_caps(request.app.state.settings)
    return {
        "versions": [_version_out(v, False) for v in found],
        # What the page says under the list: versions before `oldest_kept` were pruned.
        "oldest_kept": oldest,
        "pruned": oldest > 1,
        "kept": {
            "versions_per_file": history.versions_per_file,
            "workspace_bytes": history.workspace_bytes,
        },
    }


def _one_version(request: Request, caller: Caller, workspace: str, filename: str, number: int):
    with request.app.state.store.session() as db:
        version = store.get_version(db, caller.id, workspace, _filename(filename), number)
    if version is None:
        raise HTTPException(404, f"no version {number} of '{filename}' in '{workspace}'")
    return version


@router.get("/{workspace}/files/{filename:path}/versions/{number}", summary="One saved version")
def get_version(
    request: Request,
    number: int = VersionNumber,
    workspace: str = WorkspaceId,
    filename: str = FileName,
    caller: Caller = Depends(current_user),
) -> dict:
    return _version_out(_one_version(request, caller, workspace, filename, number))


@router.post(
    "/{workspace}/files/{filename:path}/versions/{number}/restore",
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
    history = history_caps(request.app.state.settings)
    with request.app.state.store.session() as db:
        return _version_out(store.save(db, caller.id, workspace, old.filename, old.code, history))
