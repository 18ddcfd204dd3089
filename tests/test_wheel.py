"""The wheel carries everything the installed lab reads at run time (issue 14, packaging).

A non-editable install has only the wheel's files: the pages and bundles the server serves
(web/ through the server/web_assets link), worlds, exercise reference and starter code, the
store's migrations and the sandbox's shims. The wheel is built here from a copy of the
repository's files (so a stale build/ cannot supply a missing one); ./scripts/check-wheel goes on
to install it in a fresh venv and serve the pages from there.
"""

from __future__ import annotations

import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

import server
from server.api import app as api_app

pytestmark = pytest.mark.slow  # builds the wheel and installs it

ROOT = Path(__file__).resolve().parent.parent
# What web/ must ship: the two pages and the bundles they load (not src/ or node tooling).
WEB_FILES = ("index.html", "admin.html", "static/student.js", "static/student.css",
             "static/admin.js", "static/admin.css")  # fmt: skip


def tracked(*paths: str) -> list[str]:
    listed = subprocess.run(
        ["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard", *paths],
        cwd=ROOT, capture_output=True, check=True,
    ).stdout  # fmt: skip
    return [name for name in listed.decode().split("\0") if name and (ROOT / name).exists()]


@pytest.fixture(scope="module")
def wheel_names(tmp_path_factory: pytest.TempPathFactory) -> set[str]:
    scratch = tmp_path_factory.mktemp("wheel")
    source = scratch / "src"
    for name in tracked():
        (source / name).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(ROOT / name, source / name, follow_symlinks=False)
    # Built by this environment's setuptools (the lock's), not one an isolated build fetches.
    subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "-q",
         "-w", str(scratch / "out"), "."],
        cwd=source, capture_output=True, check=True,
    )  # fmt: skip
    (wheel,) = (scratch / "out").glob("robodojo-*.whl")
    with zipfile.ZipFile(wheel) as archive:
        return set(archive.namelist())


def test_the_wheel_carries_the_pages_the_server_serves(wheel_names: set[str]) -> None:
    missing = [name for name in WEB_FILES if f"server/web_assets/{name}" not in wheel_names]
    assert missing == []
    # The built guide (/guide/), every file of it: pages, figures, search index, theme assets.
    guide = [p.relative_to(ROOT / "web").as_posix() for p in (ROOT / "web" / "guide").rglob("*")
             if p.is_file()]  # fmt: skip
    assert len(guide) > 50
    assert [n for n in guide if f"server/web_assets/{n}" not in wheel_names] == []
    assert not any(name.startswith("server/web_assets/src/") for name in wheel_names)


def test_the_wheel_carries_every_run_time_file_of_server_and_sandbox(
    wheel_names: set[str],
) -> None:
    needed = [
        name for name in tracked("server", "sandbox")
        if not name.endswith(".md") and not (ROOT / name).is_symlink()
    ]  # fmt: skip
    assert len(needed) > 100
    assert [name for name in needed if name not in wheel_names] == []


def test_the_server_reads_its_pages_from_inside_its_package() -> None:
    package = Path(server.__file__).resolve().parent
    assert api_app.WEB_DIR.parent.resolve() == package
    for name in WEB_FILES:
        assert (api_app.WEB_DIR / name).read_bytes() == (ROOT / "web" / name).read_bytes()
