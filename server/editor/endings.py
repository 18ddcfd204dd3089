"""How a request's process ended, said as its answer (host.py): a process that sent no answer
of its own (ruff's never does) is answered from its exit status, the CPU it used and what it
wrote, and one past its time budget is answered for; each refusal is a sentence for the
student that says what stopped the analysis and what in the file can cause it."""

from __future__ import annotations

import os
import signal

from server.editor.frames import Answer, Cause, Job, Op, Refused
from server.editor.limits import EditorLimits, MiB

NESTED = "very long or deeply nested code, or a long chain of expressions built from one another"


def late(job: Job, budget_s: float) -> Refused:
    """A process stopped at its time budget."""
    what = "formatting" if job.op is Op.RUFF_FORMAT else "analysis"
    return Refused(job.id, Cause.TIME,
                   f"the {what} of this file took longer than its {budget_s:g} s and was "
                   f"stopped; {NESTED}, can cause this")  # fmt: skip


def _out_of_cpu(signal_number: int | None, cpu_s: float, budget_s: float,
                limits: EditorLimits) -> bool:  # fmt: skip
    # SIGKILL is RLIMIT_CPU's second step, or the memory cgroup's killer; the CPU used tells.
    return signal_number == signal.SIGXCPU or (
        signal_number == signal.SIGKILL and cpu_s >= limits.cpu_seconds(budget_s)
    )


def analysis_ended(job: Job, budget_s: float, status: int, cpu_s: float,
                   limits: EditorLimits) -> Refused:  # fmt: skip
    """An analysis process that ended before its answer."""
    signal_number = os.WTERMSIG(status) if os.WIFSIGNALED(status) else None
    if _out_of_cpu(signal_number, cpu_s, budget_s, limits):
        return Refused(job.id, Cause.CPU,
                       f"the analysis of this file used its {budget_s:g} s of CPU time and was "
                       "stopped; very long or deeply nested code can cause this")  # fmt: skip
    if signal_number == signal.SIGKILL:
        return Refused(job.id, Cause.MEMORY,
                       "the analysis ran out of memory on this file and was stopped; very long "
                       "or deeply nested code can cause this")  # fmt: skip
    return Refused(job.id, Cause.FAILED,
                   "the analysis stopped on this file; very long or deeply nested code can "
                   "cause this")  # fmt: skip


def ruff_ended(job: Job, budget_s: float, status: int, cpu_s: float, out: bytes, err: bytes,
               truncated: bool, limits: EditorLimits) -> Answer | Refused:  # fmt: skip
    """Ruff's process: its output as the answer, or why there is none."""
    stderr = err.decode(errors="replace")
    exit_code = os.WEXITSTATUS(status) if os.WIFEXITED(status) else None
    signal_number = os.WTERMSIG(status) if os.WIFSIGNALED(status) else None
    # 0: done; 1 and 2: ruff's own "found something" and "could not" (a syntax error); 101 is
    # a panic, 127 our exec failing.
    if truncated or (exit_code in (0, 1, 2) and "panicked" not in stderr):
        return Answer(job.id, {
            "returncode": 0 if truncated else exit_code,
            "stdout": out.decode(errors="replace"),
            "stderr": stderr[-4096:],
            "truncated": truncated,
        })  # fmt: skip
    what = "formatter" if job.op is Op.RUFF_FORMAT else "linter"
    out_of_cpu = _out_of_cpu(signal_number, cpu_s, budget_s, limits)
    # Out of address space ruff panics (a stack it cannot map) or aborts (an allocation), or
    # dies of SIGSEGV on a guard page; the memory cgroup's killer sends SIGKILL.
    if (
        "Cannot allocate memory" in stderr
        or "memory allocation" in stderr
        or (signal_number in (signal.SIGSEGV, signal.SIGKILL) and not out_of_cpu)
    ):
        return Refused(job.id, Cause.MEMORY,
                       f"the {what} ran out of its {limits.ruff_memory_bytes // MiB} MiB of "
                       "memory on this file and was stopped; very long or deeply nested "
                       "expressions can cause this")  # fmt: skip
    if out_of_cpu:
        return Refused(job.id, Cause.CPU,
                       f"the {what} used its {budget_s:g} s of CPU time on this file and was "
                       "stopped")  # fmt: skip
    # A stack overflow (SIGABRT: 100,000 terms in one f-string's expression) lands here.
    return Refused(
        job.id, Cause.FAILED, f"the {what} stopped on this file; {NESTED}, can cause this"
    )
