"""One budget per student for every sandbox job (issue 33, finding 4): a run's nodes and a launch
file being read count together against `max_sandbox_jobs_per_student` jobs at once and
`student_sandbox_memory_bytes` of memory, each sandbox counted at its memory cap
(sandbox/limits.py `memory_bytes`: what it may take before its cgroup stops it). A job past
either is refused with a sentence; the run service answers it as a run over the run limits is
(429 with Retry-After), or 422 when the job would not fit even alone.

Only runs were limited before: 8 parallel starts of a run whose `.launch.py` spun in a 300 MiB
list read 8 launch files at once (36 sandboxes counted over the attack, +2.6 GiB), while the
runs themselves were held to 2.

Pure: the store says what the student holds (server/store/sandbox_leases.py `Holding`), this
says whether one more job fits.

    budget = SandboxBudget.from_settings(settings, launcher.limits.memory_bytes)
    refusal = budget.refusal(held, sandboxes=3, what="this run's 3 nodes")
"""

from __future__ import annotations

from dataclasses import dataclass

from server.store.sandbox_leases import Holding

GIB = 1024**3
MIB = 1024**2


def _size(size_bytes: int) -> str:
    if size_bytes >= GIB:
        return f"{size_bytes / GIB:.1f} GiB"
    return f"{size_bytes / MIB:.0f} MiB"


def _count(number: int, what: str, plural: str | None = None) -> str:
    return f"{number} {what if number == 1 else plural or what + 's'}"


@dataclass(frozen=True, slots=True)
class Refusal:
    sentence: str
    waiting_helps: bool  # False: the job is larger than the whole budget


@dataclass(frozen=True, slots=True)
class SandboxBudget:
    max_jobs: int  # sandbox jobs of one student at once (a run is one job)
    memory_bytes: int  # [B] their sandboxes' memory caps together; 0 = no memory budget
    sandbox_memory_bytes: int  # [B] one sandbox's memory cap

    @classmethod
    def from_settings(cls, settings, sandbox_memory_bytes: int) -> SandboxBudget:
        return cls(
            max_jobs=settings.max_sandbox_jobs_per_student,
            memory_bytes=settings.student_sandbox_memory_bytes,
            sandbox_memory_bytes=sandbox_memory_bytes,
        )

    def refusal(self, held: Holding, sandboxes: int, what: str) -> Refusal | None:
        """Why one more job of `sandboxes` sandboxes (`what`, for the sentence) does not fit
        beside what the student holds, or None when it does."""
        cap = self.sandbox_memory_bytes
        needs = sandboxes * cap
        taking = f"{what} would take {_count(sandboxes, 'sandbox', 'sandboxes')} of up to"
        if self.memory_bytes and needs > self.memory_bytes:
            return Refusal(
                f"{taking} {_size(cap)} each ({_size(needs)}), more than a student's budget of "
                f"{_size(self.memory_bytes)} at once; use fewer nodes",
                waiting_helps=False,
            )
        if held.jobs >= self.max_jobs:
            return Refusal(
                f"you already have {_count(held.jobs, 'sandbox job')} going "
                f"({_count(held.runs, 'run')}, {_count(held.leases, 'launch file')} being "
                f"read); the limit is {self.max_jobs} at once: wait for one to end, or stop a run",
                waiting_helps=True,
            )
        total = (held.sandboxes + sandboxes) * cap
        if self.memory_bytes and total > self.memory_bytes:
            return Refusal(
                f"{taking} {_size(cap)} each; with the {held.sandboxes} your runs and jobs "
                f"hold now that is {_size(total)}, over your budget of "
                f"{_size(self.memory_bytes)}: wait for a run to end, or stop one",
                waiting_helps=True,
            )
        return None
