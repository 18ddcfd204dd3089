"""Hooks around the student's imports: patch a module once it is imported, or hear that one of
a few modules is about to be.

    hook = AfterImport("matplotlib.figure", patch)   # patch(module) now if already imported,
    hook.install()                                   # else right after the student imports it
    ...
    hook.remove()

    heavy = BeforeImport({"numpy", "matplotlib"}, announce)   # announce() when the student
    heavy.install()                                           # starts importing one of them

A node started cold does not import matplotlib ahead (sandbox/runner.py); the node host still
has to wrap `Figure.savefig` (sandbox/host.py) before the student's first figure is saved, and
the parent must know that a step is importing a heavy library (it may take longer than a step
budget). Both hooks are finders at the front of `sys.meta_path`: `AfterImport` lets the other
finders find the module and wraps the loader they return, so the module loads from the same
file as without it; `BeforeImport` only listens and finds nothing.
"""

from __future__ import annotations

import importlib.machinery
import sys
import types
from collections.abc import Callable, Sequence
from typing import Any

Patch = Callable[[types.ModuleType], None]


class _PatchingLoader:
    """The real loader, and `patch` once the module's code has run. (The import protocol needs
    the methods, not the importlib.abc base classes, whose import costs a node ~15 ms.)"""

    def __init__(self, inner: Any, patch: Patch) -> None:
        self._inner = inner
        self._patch = patch

    def create_module(self, spec: importlib.machinery.ModuleSpec) -> types.ModuleType | None:
        return self._inner.create_module(spec)

    def exec_module(self, module: types.ModuleType) -> None:
        module.__loader__ = self._inner  # get_source and friends: the real loader's
        self._inner.exec_module(module)
        self._patch(module)

    def __getattr__(self, name: str) -> object:
        return getattr(self._inner, name)


class _MetaPathHook:
    """A finder at the front of sys.meta_path, put there once and taken out again."""

    def install(self) -> None:
        if self not in sys.meta_path:
            sys.meta_path.insert(0, self)

    def remove(self) -> None:
        if self in sys.meta_path:
            sys.meta_path.remove(self)


class AfterImport(_MetaPathHook):
    """Calls `patch(module)` once `name` is imported (at once if it already is)."""

    def __init__(self, name: str, patch: Patch) -> None:
        self.name = name
        self._patch = patch

    def install(self) -> None:
        module = sys.modules.get(self.name)
        if module is not None:
            self._patch(module)
            return
        super().install()

    def find_spec(
        self,
        fullname: str,
        path: Sequence[str] | None,
        target: types.ModuleType | None = None,
    ) -> importlib.machinery.ModuleSpec | None:
        if fullname != self.name:
            return None
        self.remove()  # once is enough, and the finders below must not find us again
        for finder in sys.meta_path:
            find = getattr(finder, "find_spec", None)
            spec = find(fullname, path, target) if find is not None else None
            if spec is not None:
                if spec.loader is not None:
                    spec.loader = _PatchingLoader(spec.loader, self._patch)
                return spec
        return None


class BeforeImport(_MetaPathHook):
    """Calls `announce()` when a top-level package in `names` is about to be imported for the
    first time in this process (a package already in sys.modules is never searched for)."""

    def __init__(self, names: set[str], announce: Callable[[], None]) -> None:
        self.names = frozenset(names)
        self._announce = announce

    def find_spec(
        self,
        fullname: str,
        path: Sequence[str] | None,
        target: types.ModuleType | None = None,
    ) -> None:
        if fullname in self.names:
            self._announce()
        return None  # the other finders find it
