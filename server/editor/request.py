"""A request's process: what runs in a process the host (host.py) forked, from its start to its
exit. It limits and seals itself (sandbox/editor_walls.py) before it reads the student's text
and never returns into the host's code.

A process is forked before its job comes, as a spare: it limits and seals itself at once and
waits on its job pipe, exiting when the host closes it. An analysis process then answers the
jobs of one student, the one its first job was for, one after another, as long as the host
keeps it (server/editor/limits.py, `sessions`): their own texts only, whose analyses share
jedi's caches and its parser's last look at the file. Measured on the 2-core lab machine at
load 5, a completion of a 45-line rospy node: 65 ms in a student's process against 112 ms in a
process forked for each request (71 ms in the host itself). Each job still has its own time
budget (the host's deadline) and CPU seconds (`next_cpu_limit`). A ruff process runs ruff for
one job and is gone.

Spares that also analysed a text of ours ahead, so that the pages of the host's memory jedi
touches would be copied before the job, were tried and dropped: the job was quicker, but the
warm-up took more of the machine than it saved, and on a loaded one completions got slower.
"""

from __future__ import annotations

import contextlib
import fcntl
import mmap
import os
import resource

from sandbox.editor_walls import limit_request, next_cpu_limit, seal_request
from sandbox.protocol import FrameReader, FrameWriter, ProtocolError
from server.editor.frames import Cause, Done, Job, Op, Parsed, ToHost
from server.editor.limits import EditorLimits

NOTHING = {Op.COMPLETE: {"completions": [], "signature": None}, Op.HOVER: {"text": None}}
TOO_DEEP = ("the code is nested too deeply or is too large to analyse; split long expressions "
            "and deep nesting")  # fmt: skip
ANSWER_FD, JOB_FD = 3, 4  # an analysis process's pipes, moved here before anything else


def analysis_process(
    analyser,
    limits: EditorLimits,
    job_fd: int,
    answer_fd: int,
    budget_s: float,
    nice: int = 0,
) -> None:
    """Checks, completion or hover for the job that comes on `job_fd`, in `budget_s` of CPU
    time, `nice` lower in priority than the host. Never returns."""
    status = 1
    try:
        _keep_only({0: os.open(os.devnull, os.O_RDONLY), 1: 2, ANSWER_FD: answer_fd,
                    JOB_FD: job_fd})  # fmt: skip
        writer = FrameWriter(ANSWER_FD)
        _report_parses(writer)
        os.nice(nice)
        limit_request(
            _mapped_bytes() + limits.request_memory_bytes,
            limits.cpu_seconds(budget_s),
            limits.request_open_files,
            limits.session_cpu_seconds,
        )
        seal_request(runs_program=False)
        # The jobs of one student, until the host closes the pipe (module docstring).
        while (job := _read_job()) is not None:
            next_cpu_limit(limits.cpu_seconds(budget_s))
            done = _answer(analyser, limits, job)
            writer.send(done)
            if done.result is None:
                break  # after a failure (its memory cap, say) the process does not go on
        status = 0
    finally:
        os._exit(status)


def _answer(analyser, limits: EditorLimits, job: Job) -> Done:
    from server.editor.api_checks import check
    from server.editor.context import topics_from_json
    from server.editor.syntax import parse

    try:
        extra = topics_from_json(job.extra_topics)
        parsed = parse(job.code)
        if job.op is Op.CHECKS:
            found = check(job.code, parsed.tree, job.robot, extra) if parsed.tree else []
            return Done({
                "diagnostics": [d.to_json() for d in found[: limits.max_diagnostics]],
                "syntax": [d.to_json() for d in parsed.problems],
            })  # fmt: skip
        if parsed.too_deep:  # jedi would only run into the time limit
            return Done(NOTHING[job.op])
        if job.op is Op.COMPLETE:
            return Done(analyser.complete(job.code, job.line, job.column, job.robot, extra))
        return Done(analyser.hover(job.code, job.line, job.column, job.robot, extra))
    except (RecursionError, MemoryError):
        return Done(error=TOO_DEEP, cause=Cause.MEMORY)
    except Exception as error:  # jedi's own faults on odd text: a sentence
        return Done(error=f"the analysis failed on this text ({type(error).__name__}); it "
                    "still runs as usual")  # fmt: skip


def ruff_process(ruff: str, limits: EditorLimits, job_fd: int, out_fd: int, err_fd: int) -> None:
    """Ruff for the job that comes on `job_fd`: the text on its stdin, then ruff itself, with
    the job's limits. Never returns."""
    from server.editor.ruff_tool import CHECK_ARGUMENTS, FORMAT_ARGUMENTS

    try:
        _keep_only({0: os.open(os.devnull, os.O_RDONLY), 1: out_fd, 2: err_fd, JOB_FD: job_fd})
        job = _read_job()
        if job is None:
            os._exit(0)
        code = os.memfd_create("student-code", 0)  # not a pipe: it would fill before the exec
        data = memoryview(job.code.encode())
        while data:
            data = data[os.write(code, data) :]
        os.lseek(code, 0, os.SEEK_SET)
        os.dup2(code, 0)
        os.close(code)
        os.close(JOB_FD)
        budget_s = limits.ruff_budget_s if job.op is Op.RUFF_CHECK else limits.format_budget_s
        arguments = CHECK_ARGUMENTS if job.op is Op.RUFF_CHECK else FORMAT_ARGUMENTS
        seal_request(runs_program=True)
        limit_request(limits.ruff_memory_bytes, limits.cpu_seconds(budget_s),
                      limits.request_open_files)  # fmt: skip
        os.execv(ruff, [ruff, *arguments])
    finally:
        os._exit(127)


def _keep_only(fds: dict[int, int]) -> None:
    """Put each source fd at its target number and close every other descriptor (the host's
    pipes to the server and to other requests). The copies go above every target first, so
    that no move overwrites a source still to be moved."""
    top = max(fds) + 1
    copies = {target: fcntl.fcntl(source, fcntl.F_DUPFD, top) for target, source in fds.items()}
    for target, copy in copies.items():
        os.dup2(copy, target)
    for fd in range(top):
        if fd not in fds:
            with contextlib.suppress(OSError):
                os.close(fd)
    os.closerange(top, resource.getrlimit(resource.RLIMIT_NOFILE)[0])


def _read_job() -> Job | None:
    """The job frame from the host, or None if it closed the pipe (a spare it let go)."""
    try:
        job = FrameReader(JOB_FD, ToHost).receive()
    except ProtocolError:
        return None
    return job if isinstance(job, Job) else None


def _mapped_bytes() -> int:
    """This process's address space [bytes], found without /proc (the editor's sandbox has
    none): the lowest RLIMIT_AS under which one more page can still be mapped, by bisection
    (~40 setrlimit and mmap calls, well under a millisecond)."""
    page = mmap.PAGESIZE
    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    low, high = 0, hard if hard != resource.RLIM_INFINITY else 1 << 47
    try:
        while high - low > page:  # mapping a page fails at `low`, works at `high`
            middle = (low + high) // 2 // page * page
            resource.setrlimit(resource.RLIMIT_AS, (middle, hard))
            try:
                mmap.mmap(-1, page).close()
                high = middle
            except (OSError, MemoryError):
                low = middle
    finally:
        resource.setrlimit(resource.RLIMIT_AS, (soft, hard))
    return high - page


def _report_parses(writer: FrameWriter) -> None:
    """parso writes no cache file here (it could not: the process is sealed) and tells the
    host what it parsed, or read from the disk cache, instead (`Parsed`)."""
    import parso.cache as parse_cache

    load = parse_cache._load_from_file_system

    def report(hashed_grammar, path, item=None, cache_path=None):
        writer.send(Parsed(grammar=hashed_grammar, path=str(path)))

    def load_and_report(hashed_grammar, path, p_time, cache_path=None):
        module = load(hashed_grammar, path, p_time, cache_path=cache_path)
        if module is not None:
            report(hashed_grammar, path)
        return module

    parse_cache._save_to_file_system = report
    parse_cache._load_from_file_system = load_and_report
    parse_cache._remove_cache_and_update_lock = lambda cache_path=None: None
