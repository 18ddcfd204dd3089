"""The launch job: what the node host does with `Load(api=Api.LAUNCH)`. It writes the
workspace into its working directory, evaluates the launch file (evaluate.py) with the
arguments of `info.argv`, and ends with an Exited frame that carries the plan as the artifact
`launch_plan.json`, or a LaunchFileError with the launch file's line. It never yields: the
whole evaluation runs within the first-step budget, so a launch file that loops is killed."""

from __future__ import annotations

import errno
import os
import socket
import traceback

import msgspec

from sandbox.artifacts import write_workspace_files
from sandbox.launch2.errors import LAUNCH_FILES, LaunchError, PackageNotFoundError
from sandbox.launch2.evaluate import evaluate
from sandbox.launch2.plan import PLAN_ARTIFACT
from sandbox.protocol import Artifact, Exited, Load, NodeError, Outcome

ERROR_TYPE = "LaunchFileError"


def _error(message: str, filename: str, line: int | None) -> Exited:
    where = f" (line {line})" if line else ""
    return Exited(
        outcome=Outcome.ERROR,
        reason=f"{filename}{where}: {message}",
        error=NodeError(
            type=ERROR_TYPE, message=message, filename=filename, line=line, traceback=""
        ),
    )


def _student_error(error: BaseException, main_file: str) -> Exited:
    """Anything the launch file's own code raised, at its innermost launch-file line."""
    if isinstance(error, SyntaxError) and error.filename in LAUNCH_FILES:
        return _error(f"invalid Python: {error.msg}", error.filename, error.lineno)
    frames = [
        frame
        for frame in traceback.extract_tb(error.__traceback__)
        if frame.filename in LAUNCH_FILES
    ]
    filename, line = (frames[-1].filename, frames[-1].lineno) if frames else (main_file, None)
    message = f"{type(error).__name__}: {error}"
    if isinstance(error, SystemExit):
        message = "the launch file called sys.exit(); generate_launch_description() returns"
    elif isinstance(error, socket.gaierror) or (
        isinstance(error, OSError) and error.errno == errno.EPERM
    ):
        message += (
            " (a launch file is read in the sandbox: it cannot open network connections or "
            "start programs)"
        )
    elif isinstance(error, KeyError) and frames and _environment_lookup(error):
        message += (
            " (the launch file reads an environment variable; a run has none: use a launch "
            "argument, or os.environ.get('NAME', 'default'))"
        )
    elif isinstance(error, RecursionError):
        message = "RecursionError: the launch description nests too deeply (an endless include?)"
    return _error(message, filename, line)


def _environment_lookup(error: KeyError) -> bool:
    """Whether a KeyError came from os.environ[...] (its last frame is in the os module)."""
    last = traceback.extract_tb(error.__traceback__)[-1]
    return last.filename == "<frozen os>" or os.path.basename(last.filename) == "os.py"


def run_launch(load: Load, workdir: str) -> Exited:
    write_workspace_files(workdir, [*load.files, Artifact(load.filename, load.code.encode())])
    try:
        plan = evaluate(load.filename, workdir, list(load.info.argv))
    except LaunchError as error:
        site = error.site
        return _error(str(error), site.filename if site else load.filename, site and site.line)
    except PackageNotFoundError as error:
        site = error.site
        return _error(str(error), site.filename if site else load.filename, site and site.line)
    except BaseException as error:  # the launch file's own code: never ours to re-raise
        return _student_error(error, load.filename)
    data = msgspec.json.encode(plan)
    return Exited(
        outcome=Outcome.FINISHED,
        reason=f"launch file read: {len(plan.nodes)} node(s)",
        artifacts=[Artifact(PLAN_ARTIFACT, data)],
    )
