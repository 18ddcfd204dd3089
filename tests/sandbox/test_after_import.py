"""sandbox.after_import: a module gets its patch whether it was imported before or after; a
first import of a listed package is announced, and only that."""

from __future__ import annotations

import sys
import types
from pathlib import Path

import pytest

from sandbox.after_import import AfterImport, BeforeImport


@pytest.fixture
def package(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> str:
    """A fresh package `afterpkg` with a submodule `figure` defining `Figure`, on sys.path."""
    root = tmp_path / "afterpkg"
    root.mkdir()
    (root / "__init__.py").write_text("")
    (root / "figure.py").write_text("class Figure:\n    def save(self):\n        return 'saved'\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    yield "afterpkg.figure"
    for name in ("afterpkg.figure", "afterpkg"):
        sys.modules.pop(name, None)


def test_a_later_import_is_patched_once_from_its_own_file(package: str) -> None:
    seen: list[types.ModuleType] = []
    hook = AfterImport(package, seen.append)
    hook.install()
    try:
        assert seen == []  # not imported yet
        import afterpkg.figure  # type: ignore[import-not-found]

        assert seen == [afterpkg.figure]
        assert afterpkg.figure.__file__.endswith("afterpkg/figure.py")
        assert type(afterpkg.figure.__loader__).__name__ == "SourceFileLoader"
        assert afterpkg.figure.Figure().save() == "saved"
        assert hook not in sys.meta_path  # it removed itself after the one import
    finally:
        hook.remove()


def test_an_imported_module_is_patched_at_once(package: str) -> None:
    import afterpkg.figure  # type: ignore[import-not-found]

    seen: list[types.ModuleType] = []
    hook = AfterImport(package, seen.append)
    hook.install()
    assert seen == [afterpkg.figure]
    assert hook not in sys.meta_path


def test_removed_before_the_import_nothing_is_patched(package: str) -> None:
    seen: list[types.ModuleType] = []
    hook = AfterImport(package, seen.append)
    hook.install()
    hook.remove()
    import afterpkg.figure  # type: ignore[import-not-found]  # noqa: F401

    assert seen == []
    assert hook not in sys.meta_path


def test_other_imports_pass_through(package: str) -> None:
    hook = AfterImport(package, lambda module: None)
    hook.install()
    try:
        import afterpkg  # type: ignore[import-not-found]

        assert "afterpkg.figure" not in sys.modules
        assert hook in sys.meta_path  # still waiting for its module
        assert afterpkg.__spec__.loader is not None
    finally:
        hook.remove()


def test_a_first_import_of_a_listed_package_is_announced_once(package: str) -> None:
    heard: list[str] = []
    hook = BeforeImport({"afterpkg"}, lambda: heard.append("import"))
    hook.install()
    try:
        import json  # noqa: F401  # not listed (and imported already)

        assert heard == []
        import afterpkg.figure  # type: ignore[import-not-found]

        assert heard == ["import"]  # the package, not its submodule
        assert afterpkg.figure.Figure().save() == "saved"  # found by the other finders
        import afterpkg  # type: ignore[import-not-found]

        assert heard == ["import"]  # in sys.modules now: no search, no announcement
    finally:
        hook.remove()
    assert hook not in sys.meta_path
