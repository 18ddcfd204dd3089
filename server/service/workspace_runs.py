"""A run started from a student's workspace: what the workspace holds (saved files over the
exercise's starter code), the nodes a launch file of it names (read by server/runs/launch.py,
the reader the CLI shares), and the data files every node finds in its working directory.

Everything is looked up under the caller's own user id: a workspace id names an exercise or a
robot, never another student's files, so "launch someone else's workspace" cannot be said."""

from __future__ import annotations

from collections.abc import Mapping

from sqlalchemy.orm import Session as Db

from server.runs.spec import NodeSpec
from server.service import exercises, workspace_files
from server.service.catalog import UnknownIdError
from server.service.runs import RunRequestError
from server.sim import robot_ids
from server.store import workspaces as store

LAUNCH_EXTENSIONS = (".launch", ".xml")


def starter_files(db: Db, workspace: str) -> list[tuple[str, str]]:
    """(file name, code) an empty workspace starts from; UnknownIdError (a 404) for a workspace
    id that is neither an exercise nor a robot."""
    if workspace in robot_ids():
        return []
    try:
        entry = exercises.find(db, workspace)
    except UnknownIdError as error:
        raise UnknownIdError(
            "workspace (an exercise or robot)", workspace, [*error.valid, *robot_ids()]
        ) from None
    return [(f"{name}.py", code) for name, _, code in entry.starter]


def contents(db: Db, user_id: str, workspace: str) -> dict[str, str]:
    """File name -> text of the user's workspace: the newest saved versions, and the starter
    files not saved yet (as the editor shows them)."""
    files = dict(starter_files(db, workspace))
    files.update((v.filename, v.code) for v in store.latest_files(db, user_id, workspace))
    return files


def launch_nodes(
    files: Mapping[str, str], launch_file: str, args: Mapping[str, str]
) -> tuple[tuple[NodeSpec, ...], dict[str, object]]:
    """The nodes (with their params, remaps, args and namespaces) and the global parameters of
    a launch file of the workspace `files`; RunRequestError (a 422) with the reader's sentence,
    which names the file and line, for anything wrong in it."""
    name = workspace_files.file_name(launch_file)
    if not name.endswith(LAUNCH_EXTENSIONS):
        raise RunRequestError(
            f"'{launch_file}' is not a launch file; give a .launch (or .xml) file of the workspace"
        )
    if name not in files:
        found = sorted(f for f in files if f.endswith(LAUNCH_EXTENSIONS))
        raise RunRequestError(
            f"there is no launch file '{name}' in your workspace; "
            + (f"its launch files: {', '.join(found)}" if found else "it has no launch file yet")
        )
    from server.runs.launch import LaunchFileError, load_launch

    try:
        plan = load_launch(name, files, dict(args))
    except LaunchFileError as error:
        raise RunRequestError(str(error)) from None
    return tuple(plan.nodes), dict(plan.params)
