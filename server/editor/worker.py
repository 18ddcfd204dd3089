"""An analysis worker: a child process that answers the editor's requests (our API checks,
completion, hover) one at a time, as JSON lines on stdin/stdout. The server kills and replaces
it when a request takes too long or it dies (pool.py), so a hostile file can cost a worker,
never the server.

    python -m server.editor.worker STUB_ROOT JEDI_CACHE_DIR
"""

from __future__ import annotations

import json
import os
import pickle
import resource
import sys
import threading
import time
from pathlib import Path

from server.editor.limits import LIMITS

# What a fresh worker analyses before it says it is ready: jedi's first look at rospy, rclpy,
# the message stubs and numpy costs seconds; a student's first request should not pay it.
WARM_BEFORE_READY = (
    ("import rospy\nimport numpy as np\nfrom geometry_msgs.msg import Twist\n"
     "from sensor_msgs.msg import LaserScan\ncmd = Twist()\ncmd.linear.\nrospy.\nnp.\n",
     ((6, 11), (7, 6), (8, 3))),
    ("import rclpy\nfrom rclpy.node import Node\nfrom geometry_msgs.msg import Twist\n"
     "class N(Node):\n    def f(self):\n        self.\n        Twist().linear.\n",
     ((6, 13), (7, 23))),
    ("def step(obs):\n    obs.\n", ((2, 8),)),
)  # fmt: skip

NOTHING = {"complete": {"completions": [], "signature": None}, "hover": {"text": None}}


def _safe_parse_cache() -> None:
    """parso (jedi's parser) writes its disk cache in place and reads it trusting it whole; a
    worker killed while writing leaves a cut-short file that made every later worker fail.
    Here a cache file is written whole or not at all, and one that cannot be read is a miss."""
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


def _end_with_the_server() -> None:
    """Die with the server that started us instead of warming up for one that was killed (a
    closed stdin is only seen once the warm-up is over). Not prctl(PR_SET_PDEATHSIG): that
    follows the server's thread that started us, which ends at once."""
    server = os.getppid()

    def watch() -> None:
        while os.getppid() == server:
            time.sleep(1.0)
        os._exit(0)

    threading.Thread(target=watch, name="server-watch", daemon=True).start()


def _limit_memory() -> None:
    limit = LIMITS.worker_address_space_bytes
    resource.setrlimit(resource.RLIMIT_AS, (limit, limit))


def serve(stub_root: Path, cache_dir: Path) -> None:
    from server.editor.api_checks import check
    from server.editor.complete import Analyser
    from server.editor.context import topics_from_json
    from server.editor.syntax import parse
    from server.sim import robot_ids

    analyser = Analyser(stub_root, robot_ids(), cache_dir)
    out = os.fdopen(os.dup(sys.stdout.fileno()), "w", encoding="utf-8")
    sys.stdout = sys.stderr  # a stray print from a library must not break the protocol

    def answer(message: dict) -> None:
        out.write(json.dumps(message) + "\n")
        out.flush()

    def handle(request: dict) -> dict:
        op, code, robot = request["op"], request["code"], request.get("robot")
        extra = topics_from_json(request.get("extra_topics"))
        parsed = parse(code)
        if op == "checks":
            found = check(code, parsed.tree, robot, extra) if parsed.tree else []
            return {
                "diagnostics": [d.to_json() for d in found],
                "syntax": [d.to_json() for d in parsed.problems],
            }
        if parsed.too_deep:  # jedi would only run into the time limit
            return NOTHING[op]
        if op == "complete":
            return analyser.complete(code, request["line"], request["column"], robot, extra)
        if op == "hover":
            return analyser.hover(code, request["line"], request["column"], robot, extra)
        raise ValueError(f"unknown op {op!r}")

    for code, places in WARM_BEFORE_READY:
        for line, column in places:
            analyser.complete(code, line, column, "crowbot")
    warm_check = "from geometry_msgs.msg import Twist\ncmd = Twist()\ncmd.linear.x = 0.1\n"
    check(warm_check, parse(warm_check).tree, "crowbot")
    answer({"ready": True})
    for raw in sys.stdin:  # until the server closes our stdin: it is gone or let us go
        try:
            answer({"ok": True, "result": handle(json.loads(raw))})
        except (RecursionError, MemoryError):
            answer({"ok": False, "error": "the code is nested too deeply or is too large to "
                    "analyse; split long expressions and deep nesting"})  # fmt: skip
        except Exception as error:  # jedi's own faults on odd text: a sentence, not a dead worker
            name = type(error).__name__
            answer({"ok": False, "error": f"the analysis failed on this text ({name}); it "
                    "still runs as usual"})  # fmt: skip


if __name__ == "__main__":
    _end_with_the_server()
    _limit_memory()
    _safe_parse_cache()
    sys.setrecursionlimit(3000)  # jedi recurses on nested code; deeper fails as RecursionError
    serve(Path(sys.argv[1]), Path(sys.argv[2]))
