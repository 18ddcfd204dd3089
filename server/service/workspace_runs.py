"""A run started from a student's workspace: what the workspace holds (saved files over the
exercise's starter code), the nodes a launch file of it names (read by server/runs/launch.py,
the reader the CLI shares), and the data files every node finds in its working directory.

Everything is looked up under the caller's own user id: a workspace id names an exercise or a
robot, never another student's files, so "launch someone else's workspace" cannot be said."""

from __future__ import annotations

import logging
import uuid
from collections.abc import Callable, Mapping
from contextlib import AbstractContextManager, nullcontext

from sqlalchemy.orm import Session as Db

from sandbox.launcher import Launcher
from server.runs.launch import LaunchFileError, LaunchPlan
from server.runs.launch_py import is_python_launch, read_launch
from server.service import exercises, workspace_files
from server.service.catalog import UnknownIdError
from server.service.runs import RunRequestError
from server.sim import robot_ids
from server.store import workspaces as store

LAUNCH_EXTENSIONS = (".launch", ".xml", ".launch.py")  # ROS 1 XML; ROS 2 Python (sandboxed)
log = logging.getLogger("robodojo.service")


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


def launch_plan(
    files: Mapping[str, str],
    launch_file: str,
    args: Mapping[str, str],
    launcher: Launcher | None,
    sandbox_job: Callable[[], AbstractContextManager[None]] = nullcontext,
) -> LaunchPlan:
    """The nodes (with their params, remaps, args and namespaces), the global parameters and
    the reader's notes of a launch file of the workspace `files`; LaunchFileError (a 422 with
    the reader's sentence, which names the file and the line) for anything wrong in it. A ROS 2
    Python launch file is evaluated in a sandboxed job of `launcher`, never in this process,
    inside `sandbox_job()` (RunService.launch_file_job: the student's sandbox budget)."""
    name = workspace_files.file_name(launch_file)
    if not (name.endswith(LAUNCH_EXTENSIONS) or is_python_launch(name, files.get(name))):
        raise RunRequestError(
            f"'{launch_file}' is not a launch file; give a .launch.py (ROS 2) or .launch (ROS 1) "
            "file of the workspace"
        )
    if name not in files:
        found = sorted(f for f in files if f.endswith(LAUNCH_EXTENSIONS))
        raise RunRequestError(
            f"there is no launch file '{name}' in your workspace; "
            + (f"its launch files: {', '.join(found)}" if found else "it has no launch file yet")
        )
    # A refusal of the job (the student's sandbox budget is full) is the service's, not the
    # reader's: it is raised as it is, before the try below.
    with sandbox_job() if is_python_launch(name, files[name]) else nullcontext():
        return _read(name, files, args, launcher)


def _read(
    name: str, files: Mapping[str, str], args: Mapping[str, str], launcher: Launcher | None
) -> LaunchPlan:
    try:
        return read_launch(name, files, dict(args), launcher)
    except LaunchFileError:
        raise
    except Exception as error:  # a fault of the reader: the student still gets a sentence
        incident = uuid.uuid4().hex[:8]
        log.exception("incident %s: the launch reader failed on %s", incident, name)
        raise LaunchFileError(
            name,
            None,
            f"this launch file could not be read ({type(error).__name__}; incident {incident}, "
            "logged): check that it is a well-formed launch file, and tell your instructor the "
            "incident number",
        ) from None
