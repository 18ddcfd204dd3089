"""sandbox.after_import: a module gets its patch whether it was imported before or after; a
first import of a listed package is announced, and only that."""

from __future__ import annotations

import contextlib
import sys
import types
from pathlib import Path

import pytest

from sandbox.after_import import AfterImport, BeforeImport, DeferredImport


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


@pytest.fixture
def heavy(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> str:
    """A fresh package `deferpkg` whose submodule `heavy` counts its runs in `deferpkg.runs`."""
    root = tmp_path / "deferpkg"
    root.mkdir()
    (root / "__init__.py").write_text("runs = []\n")
    (root / "heavy.py").write_text(
        "import deferpkg\ndeferpkg.runs.append('ran')\nVALUE = 42\n\ndef double(x):\n"
        "    return 2 * x\n"
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    yield "deferpkg.heavy"
    for name in ("deferpkg.heavy", "deferpkg"):
        sys.modules.pop(name, None)


def test_a_deferred_module_runs_at_its_first_use_once(heavy: str) -> None:
    heard: list[str] = []

    @contextlib.contextmanager
    def loading():
        heard.append("loading")
        yield
        heard.append("loaded")

    hook = DeferredImport(heavy, loading)
    hook.install()
    try:
        import deferpkg.heavy as bound  # type: ignore[import-not-found]

        assert hook not in sys.meta_path  # it removed itself after the one import
        assert deferpkg_runs() == [] and heard == []  # bound, not run
        from deferpkg import heavy as again  # type: ignore[import-not-found]

        assert again is bound and deferpkg_runs() == []  # the import system only looked
        assert repr(bound).startswith("<module 'deferpkg.heavy' from ")
        assert bound.__spec__.name == heavy and deferpkg_runs() == []
        assert bound.double(21) == bound.VALUE == 42  # the first use runs it
        assert deferpkg_runs() == ["ran"] and heard == ["loading", "loaded"]
        assert type(bound) is types.ModuleType  # a plain module from now on
        assert type(bound.__loader__).__name__ == "SourceFileLoader"
        from deferpkg.heavy import double  # type: ignore[import-not-found]

        assert double(1) == 2 and deferpkg_runs() == ["ran"] and len(heard) == 2
    finally:
        hook.remove()


def test_setting_a_name_of_a_deferred_module_runs_it_first(heavy: str) -> None:
    hook = DeferredImport(heavy, contextlib.nullcontext)
    hook.install()
    import deferpkg.heavy  # type: ignore[import-not-found]

    deferpkg.heavy.VALUE = 7  # the module's own `VALUE = 42` must not overwrite it later
    assert deferpkg_runs() == ["ran"] and deferpkg.heavy.VALUE == 7


def test_a_module_imported_already_is_not_deferred(heavy: str) -> None:
    import deferpkg.heavy  # type: ignore[import-not-found]  # noqa: F401

    hook = DeferredImport(heavy, contextlib.nullcontext)
    hook.install()
    assert hook not in sys.meta_path
    assert deferpkg_runs() == ["ran"]


def test_a_deferred_module_that_fails_is_imported_again_next_time(heavy: str) -> None:
    import deferpkg  # type: ignore[import-not-found]

    source = Path(deferpkg.__file__).with_name("heavy.py")
    good = source.read_text()
    source.write_text("raise RuntimeError('broken')\n")
    hook = DeferredImport(heavy, contextlib.nullcontext)
    hook.install()
    import deferpkg.heavy as bound  # type: ignore[import-not-found]

    with pytest.raises(RuntimeError, match="broken"):
        bound.VALUE  # noqa: B018
    assert heavy not in sys.modules and not hasattr(deferpkg, "heavy")  # as a failed import
    source.write_text(good)
    import deferpkg.heavy  # type: ignore[import-not-found]

    assert deferpkg.heavy.VALUE == 42


def deferpkg_runs() -> list[str]:
    return sys.modules["deferpkg"].runs
