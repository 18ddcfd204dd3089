"""The Python code samples of the student pages, and what each one promises.

Every ```python block in a student page (docs/students/, docs/controllers.md) is preceded by a
marker that says what it is; tests/guide/test_samples.py runs each controller in the real
sandbox, unchanged, through the `robodojo` command:

    <!-- sample: robot=crowbot world=wall_approach seconds=4 -->      a whole controller: the run
                                                                      must finish without error
    <!-- sample: exercise=crowbot_distance_pid passes=a,b fails=c -->  graded on the exercise's
                                                                      seeds: these checks pass,
                                                                      those fail, as the page says
    <!-- sample: fragment -->                                        part of a controller, not
                                                                      run (say so in the text)

A block without a marker fails the test, so a new sample cannot slip in untested.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

DOCS = Path(__file__).resolve().parents[1] / "docs"
STUDENT_PAGES = (DOCS / "controllers.md", *sorted((DOCS / "students").glob("*.md")))
MARKER = re.compile(r"^<!--\s*sample:\s*(.*?)\s*-->\s*$")
FENCE = re.compile(r"^```(\w*)")
KINDS = ("robot", "world", "seconds", "exercise", "passes", "fails")


@dataclass(frozen=True)
class Sample:
    page: str  # relative to docs/
    line: int  # 1-based line of the code's first line
    code: str
    settings: dict[str, str] = field(default_factory=dict)

    @property
    def fragment(self) -> bool:
        return "fragment" in self.settings

    @property
    def where(self) -> str:
        return f"docs/{self.page}:{self.line}"

    def names(self, key: str) -> set[str]:
        return {name for name in self.settings.get(key, "").split(",") if name}


class SampleError(ValueError):
    pass


def _settings(text: str, where: str) -> dict[str, str]:
    settings: dict[str, str] = {}
    for word in text.split():
        if word == "fragment":
            settings["fragment"] = ""
            continue
        key, equals, value = word.partition("=")
        if not equals or key not in KINDS:
            raise SampleError(f"{where}: '{word}' in a sample marker; use fragment or "
                              f"{'=, '.join(KINDS)}=")  # fmt: skip
        settings[key] = value
    if "fragment" not in settings and "exercise" not in settings:
        missing = [key for key in ("robot", "world", "seconds") if key not in settings]
        if missing:
            raise SampleError(f"{where}: the sample marker needs {', '.join(missing)}")
    return settings


def samples(pages: tuple[Path, ...] = STUDENT_PAGES) -> list[Sample]:
    """Every python block of the pages with its marker; SampleError for a block without one."""
    found: list[Sample] = []
    for path in pages:
        lines = path.read_text().splitlines()
        page = path.relative_to(DOCS).as_posix()
        index = 0
        while index < len(lines):
            fence = FENCE.match(lines[index])
            if not fence:
                index += 1
                continue
            end = next((j for j in range(index + 1, len(lines)) if lines[j].startswith("```")),
                       len(lines))  # fmt: skip
            if fence.group(1) in ("python", "py"):
                where = f"docs/{page}:{index + 1}"
                before = next((lines[j] for j in range(index - 1, -1, -1) if lines[j].strip()), "")
                marker = MARKER.match(before.strip())
                if marker is None:
                    raise SampleError(
                        f"{where}: a python block without a sample marker on the line before; "
                        "add <!-- sample: robot=... world=... seconds=... --> (a whole "
                        "controller, which the tests run) or <!-- sample: fragment -->"
                    )
                code = "\n".join(lines[index + 1 : end]) + "\n"
                found.append(Sample(page, index + 2, code, _settings(marker.group(1), where)))
            index = end + 1
    return found
