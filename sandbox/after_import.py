"""Hooks around the student's imports: patch a module once it is imported, or hear that one of
a few modules is about to be.

    hook = AfterImport("matplotlib.figure", patch)   # patch(module) now if already imported,
    hook.install()                                   # else right after the student imports it
    ...
    hook.remove()

    heavy = BeforeImport({"numpy", "matplotlib"}, announce)   # announce() when the student
    heavy.install()                                           # starts importing one of them

    later = DeferredImport("matplotlib.pyplot", loading)   # `import matplotlib.pyplot` binds
    later.install()                                         # the module; its code runs at its
                                                            # first use, `with loading():`

A node started cold does not import matplotlib ahead (sandbox/runner.py); the node host still
has to wrap `Figure.savefig` (sandbox/host.py) before the student's first figure is saved, and
the parent must know that a step is importing a heavy library (it may take longer than a step
budget). Both hooks are finders at the front of `sys.meta_path`: `AfterImport` lets the other
finders find the module and wraps the loader they return, so the module loads from the same
file as without it; `BeforeImport` only listens and finds nothing.

`DeferredImport` wraps the loader too, but runs the module's code at the first use of one of
its names instead of at the import. scikit-fuzzy imports matplotlib.pyplot for its visualizer
alone: ~0.25 s of a cold node's start (a third of `import skfuzzy.control`) that a controller
which never draws need not pay. The standard `importlib.util.LazyLoader` does not do here:
Python 3.11's import statement reads `__spec__` of a module already in sys.modules, which
loads a LazyLoader module at the very next `import matplotlib.pyplot`.
"""

from __future__ import annotations

import importlib.machinery
import sys
import threading
import types
from collections.abc import Callable, Sequence
from contextlib import AbstractContextManager
from typing import Any

Patch = Callable[[types.ModuleType], None]
Loading = Callable[[], AbstractContextManager[object]]


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


def _find_spec_below(
    fullname: str, path: Sequence[str] | None, target: types.ModuleType | None
) -> importlib.machinery.ModuleSpec | None:
    """The spec the finders on sys.meta_path give (the hook asking has removed itself)."""
    for finder in sys.meta_path:
        find = getattr(finder, "find_spec", None)
        spec = find(fullname, path, target) if find is not None else None
        if spec is not None:
            return spec
    return None


class _MetaPathHook:
    """A finder at the front of sys.meta_path, put there once and taken out again."""

    def install(self) -> None:
        if self not in sys.meta_path:
            sys.meta_path.insert(0, self)

    def remove(self) -> None:
        if self in sys.meta_path:
            sys.meta_path.remove(self)


class _OneModuleHook(_MetaPathHook):
    """A finder for one module: the first time it is searched for, the hook takes itself out,
    lets the finders below find it and hands their spec to `_wrap` (to change its loader)."""

    def __init__(self, name: str) -> None:
        self.name = name

    def find_spec(
        self,
        fullname: str,
        path: Sequence[str] | None,
        target: types.ModuleType | None = None,
    ) -> importlib.machinery.ModuleSpec | None:
        if fullname != self.name:
            return None
        self.remove()  # once is enough, and the finders below must not find us again
        spec = _find_spec_below(fullname, path, target)
        if spec is not None:
            self._wrap(spec)
        return spec

    def _wrap(self, spec: importlib.machinery.ModuleSpec) -> None:
        raise NotImplementedError


class AfterImport(_OneModuleHook):
    """Calls `patch(module)` once `name` is imported (at once if it already is)."""

    def __init__(self, name: str, patch: Patch) -> None:
        super().__init__(name)
        self._patch = patch

    def install(self) -> None:
        module = sys.modules.get(self.name)
        if module is not None:
            self._patch(module)
            return
        super().install()

    def _wrap(self, spec: importlib.machinery.ModuleSpec) -> None:
        if spec.loader is not None:
            spec.loader = _PatchingLoader(spec.loader, self._patch)


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


# What the import system (and a module's repr) reads of a module without using it: a deferred
# module answers these without running its code.
_IMPORT_SYSTEM_NAMES = frozenset(
    {"__class__", "__name__", "__spec__", "__loader__", "__package__", "__file__", "__path__"}
)


class _DeferredModule(types.ModuleType):
    """A module whose code has not run yet: the first other attribute read, write or delete
    runs it (`_run_deferred`, set per module by `_DeferringLoader`), then this class is gone."""

    _run_deferred: Callable[[types.ModuleType], None]

    def __getattribute__(self, name: str) -> Any:
        if name in _IMPORT_SYSTEM_NAMES:
            return super().__getattribute__(name)
        type(self)._run_deferred(self)
        return getattr(self, name)

    def __setattr__(self, name: str, value: Any) -> None:
        if name == "__class__":  # the loader making it a plain module again
            super().__setattr__(name, value)
            return
        type(self)._run_deferred(self)
        setattr(self, name, value)

    def __delattr__(self, name: str) -> None:
        type(self)._run_deferred(self)
        delattr(self, name)


class _DeferringLoader:
    """The real loader, run at the module's first use, inside `with loading():`."""

    def __init__(self, inner: Any, loading: Loading) -> None:
        self._inner = inner
        self._loading = loading
        self._lock = threading.RLock()  # two threads using it first: one runs it, one waits

    def create_module(self, spec: importlib.machinery.ModuleSpec) -> types.ModuleType | None:
        return self._inner.create_module(spec)

    def exec_module(self, module: types.ModuleType) -> None:
        module.__loader__ = self._inner  # get_source and friends: the real loader's
        if module.__spec__ is not None:
            module.__spec__.loader = self._inner  # importlib.reload() runs it as usual
        deferred = type("DeferredModule", (_DeferredModule,), {"_run_deferred": self._run})
        module.__class__ = deferred

    def _run(self, module: types.ModuleType) -> None:
        with self._lock:
            if not isinstance(module, _DeferredModule):
                return  # another thread ran it while this one waited
            module.__class__ = types.ModuleType  # from here on a plain module being imported
            try:
                with self._loading():
                    self._inner.exec_module(module)
            except BaseException:
                # As after a failed import: gone, and the next import tries again.
                name = module.__name__
                if sys.modules.get(name) is module:
                    del sys.modules[name]
                parent_name, _, child = name.rpartition(".")
                parent = sys.modules.get(parent_name)
                if parent is not None and getattr(parent, child, None) is module:
                    delattr(parent, child)
                raise

    def __getattr__(self, name: str) -> object:
        return getattr(self._inner, name)


class DeferredImport(_OneModuleHook):
    """Makes the next import of `name` bind the module at once and run its code at its first
    use, inside `with loading():` (nothing happens if `name` is imported already)."""

    def __init__(self, name: str, loading: Loading) -> None:
        super().__init__(name)
        self._loading = loading

    def install(self) -> None:
        if self.name not in sys.modules:
            super().install()

    def _wrap(self, spec: importlib.machinery.ModuleSpec) -> None:
        if hasattr(spec.loader, "exec_module"):
            spec.loader = _DeferringLoader(spec.loader, self._loading)
