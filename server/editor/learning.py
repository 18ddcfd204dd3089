"""What requests learn, kept for the requests after them: the library modules jedi parsed in a
request's process (which dies with its answer) are parsed again in the host, on a thread of its
own, into the caches every later request inherits (host.py), and into jedi's disk cache for the
next start. Only files under the libraries' folders are parsed, never a student's text (which
is no file); a parse of a large module takes a second on a loaded machine, which the host's
loop, answering requests and enforcing their deadlines meanwhile, does not wait for.
"""

from __future__ import annotations

import contextlib
import os
import queue
import threading
from pathlib import Path

from server.editor.frames import Parsed
from server.editor.limits import MiB

LEARNABLE_BYTES = 4 * MiB  # [bytes] a library file larger than this is not learnt
LEARNER_NICE = 19  # the learner thread's niceness (Linux gives each thread its own)


class Learner:
    def __init__(self, grammars: dict, roots: tuple[str, ...], cache_dir: Path, most: int) -> None:
        """`grammars`: parso's grammars by hash (jedi's and its latest, for .pyi stubs);
        `roots`: the libraries' folders; `most`: modules learnt at most."""
        self._grammars = grammars
        self._roots = tuple(os.path.realpath(root) for root in roots)
        self._cache_dir = cache_dir
        self._most = most
        self._seen: set[tuple[str, str]] = set()
        self._queue: queue.SimpleQueue[tuple[str, str]] = queue.SimpleQueue()
        self._lock = threading.Lock()
        self._pending = 0  # noted and not parsed yet
        self._new = False  # parsed something since settled() last said so
        threading.Thread(target=self._run, name="editor-learner", daemon=True).start()

    def note(self, frame: Parsed) -> None:
        key = (frame.grammar, frame.path)
        with self._lock:
            if key in self._seen or len(self._seen) >= self._most:
                return
            self._seen.add(key)
            self._pending += 1
        self._queue.put(key)

    @property
    def pending(self) -> int:
        with self._lock:
            return self._pending

    def settled(self) -> bool:
        """True, once, when what was noted is all parsed (the host then forks new spares)."""
        with self._lock:
            if self._pending or not self._new:
                return False
            self._new = False
            return True

    def _run(self) -> None:
        # This thread only: requests, and the host's loop that answers them, come first.
        os.setpriority(os.PRIO_PROCESS, threading.get_native_id(), LEARNER_NICE)
        while True:
            hashed, path = self._queue.get()
            self._parse(hashed, path)
            with self._lock:
                self._pending -= 1
                self._new = True

    def _parse(self, hashed: str, path: str) -> None:
        grammar = self._grammars.get(hashed)
        real = os.path.realpath(path)
        if grammar is None or not real.endswith((".py", ".pyi")):
            return
        if not any(real.startswith(root + os.sep) for root in self._roots):
            return
        with contextlib.suppress(Exception):  # one jedi read and parso cannot: not learnt
            if os.path.getsize(real) <= LEARNABLE_BYTES:
                module = grammar.parse(path=path, cache=True, cache_path=self._cache_dir)
                module.get_used_names()  # jedi's next costly step on a module, kept in the tree


def safe_parse_cache() -> None:
    """parso (jedi's parser) writes its disk cache in place and reads it trusting it whole; a
    host killed while writing leaves a cut-short file that made every later one fail. Here a
    cache file is written whole or not at all, and one that cannot be read is a miss."""
    import pickle

    import parso.cache as parse_cache

    load = getattr(parse_cache, "_load_from_file_system", None)
    hashed_path = getattr(parse_cache, "_get_hashed_path", None)
    if load is None or hashed_path is None or not hasattr(parse_cache, "_save_to_file_system"):
        return  # another parso: its own cache code

    def tolerant_load(hashed_grammar, path, p_time, cache_path=None):
        try:
            return load(hashed_grammar, path, p_time, cache_path=cache_path)
        except Exception:  # cut short, or from another parso: parse the module again
            return None

    def whole_save(hashed_grammar, path, item, cache_path=None):
        target = hashed_path(hashed_grammar, path, cache_path=cache_path)
        partial = f"{target}.{os.getpid()}.partial"
        with open(partial, "wb") as file:
            pickle.dump(item, file, pickle.HIGHEST_PROTOCOL)
        os.replace(partial, target)

    parse_cache._load_from_file_system = tolerant_load
    parse_cache._save_to_file_system = whole_save
