"""A parent stand-in for sandbox.host.run_node, and the tests of that stand-in itself.

`Parent` runs run_node in a thread over a Link of two queues. Every frame crosses as msgpack
bytes through the protocol's own Struct types, so a frame that could not go over the real pipe
fails here too.
"""

from __future__ import annotations

import queue
import sys
import textwrap
import threading
from collections.abc import Callable, Iterable
from pathlib import Path

import msgspec
import pytest

from sandbox import host
from sandbox.host import run_node
from sandbox.limits import DEFAULT_LIMITS, Limits
from sandbox.msgs import Message
from sandbox.protocol import (
    Api,
    Drawing,
    Envelope,
    Exited,
    Finishing,
    GraphTopic,
    LibraryLoading,
    Load,
    NodeInfo,
    Outcome,
    ProtocolError,
    Shutdown,
    ToChild,
    ToParent,
    Wake,
    Yield,
)
from tests.sandbox.conftest import crowbot_info

TIMEOUT_S = 20.0  # [s] generous wall-clock bound on any single frame, so a bug fails, not hangs


def envelope(topic: str, message: Message) -> Envelope:
    return Envelope(topic, message._type, message.serialize())


class QueueLink:
    """The child's end of the pipes: msgpack frames through two queues."""

    def __init__(self) -> None:
        self.to_parent: queue.Queue[bytes] = queue.Queue()
        self.to_child: queue.Queue[bytes] = queue.Queue()
        self._encoder = msgspec.msgpack.Encoder()
        self._decoder = msgspec.msgpack.Decoder(ToChild)

    def send(self, frame: object) -> None:
        self.to_parent.put(self._encoder.encode(frame))

    def receive(self) -> object:
        try:
            data = self.to_child.get(timeout=TIMEOUT_S)
        except queue.Empty:
            raise ProtocolError("test parent sent nothing") from None
        if data == b"":
            raise ProtocolError("the other side closed the pipe")
        return self._decoder.decode(data)


class Parent:
    """Loads code into run_node (in a thread) and speaks the protocol to it."""

    def __init__(
        self,
        code: str,
        workdir: Path,
        *,
        info: NodeInfo | None = None,
        api: Api = Api.AUTO,
        filename: str = "node.py",
        limits: Limits = DEFAULT_LIMITS,
    ) -> None:
        self.link = QueueLink()
        self._decoder = msgspec.msgpack.Decoder(ToParent)
        self._encoder = msgspec.msgpack.Encoder()
        self.crash: BaseException | None = None
        self.finishing: Finishing | None = None
        self.drawings = 0  # Drawing frames seen (a figure being saved)
        self.library_loads: list[bool] = []  # LibraryLoading frames seen (their `done`)
        load = Load(textwrap.dedent(code), filename, api, info or crowbot_info("student"))

        def child() -> None:
            try:
                exited = run_node(self.link, load, str(workdir), limits)
                self.link.send(exited)
            except BaseException as error:  # surfaced to the test by next()
                self.crash = error
                self.link.to_parent.put(b"")

        self._thread = threading.Thread(target=child, daemon=True)
        self._thread.start()

    def next(self) -> Yield | Exited:
        """The node's next Yield or its Exited; a Finishing on the way is kept in
        `self.finishing` (what the node published last, e.g. from its shutdown hooks)."""
        while True:
            data = self.link.to_parent.get(timeout=TIMEOUT_S)
            if data == b"":
                assert self.crash is not None
                raise self.crash
            frame = self._decoder.decode(data)
            if isinstance(frame, Drawing):
                self.drawings += 1
                continue
            if isinstance(frame, LibraryLoading):
                self.library_loads.append(frame.done)
                continue
            if isinstance(frame, Finishing):
                assert self.finishing is None, "a node finishes once"
                self.finishing = frame
                continue
            assert isinstance(frame, Yield | Exited), frame
            if isinstance(frame, Exited):
                self._thread.join(TIMEOUT_S)
            return frame

    def last_published(self, exited: Exited) -> list[Envelope]:
        """What the node published after its last sleep: with its Finishing and its Exited."""
        before = self.finishing.published if self.finishing is not None else []
        return [*before, *exited.published]

    def wake(
        self,
        time_s: float,
        deliveries: Iterable[Envelope] = (),
        graph: list[GraphTopic] | None = None,
    ) -> Yield | Exited:
        self.link.to_child.put(self._encoder.encode(Wake(time_s, list(deliveries), graph)))
        return self.next()

    def shutdown(self, reason: str = "stop pressed") -> Exited:
        self.link.to_child.put(self._encoder.encode(Shutdown(reason)))
        frame = self.next()
        assert isinstance(frame, Exited), frame
        return frame

    def run_lockstep(
        self,
        sensors: Callable[[float], list[Envelope]] = lambda t: [],
        *,
        max_wakes: int = 1000,
        spin_period_s: float = 0.05,
    ) -> tuple[list[Yield], Exited]:
        """Wake the node at each time it asks for (spin: every `spin_period_s`) until it exits."""
        yields: list[Yield] = []
        frame = self.next()
        now = 0.0
        while isinstance(frame, Yield):
            yields.append(frame)
            assert len(yields) <= max_wakes, "the node kept sleeping"
            now = frame.wake_at_s if frame.wake_at_s is not None else now + spin_period_s
            frame = self.wake(now, sensors(now))
        return yields, frame


def run(code: str, workdir: Path, **kwargs: object) -> tuple[list[Yield], Exited]:
    """Run `code` to its end; the Exited's `published` is everything published after the last
    sleep (the Finishing's messages, from shutdown hooks, then the Exited's own)."""
    parent = Parent(code, workdir, **kwargs)  # type: ignore[arg-type]
    yields, exited = parent.run_lockstep()
    return yields, msgspec.structs.replace(exited, published=parent.last_published(exited))


def test_a_script_that_never_sleeps_finishes_with_what_it_published(tmp_path: Path) -> None:
    parent = Parent(
        """
        import rospy
        from std_msgs.msg import Bool
        rospy.init_node("beeper")
        rospy.Publisher("Buzzer", Bool, queue_size=1).publish(True)
        """,
        tmp_path,
    )
    yields, exited = parent.run_lockstep()
    assert yields == []
    assert exited.outcome is Outcome.FINISHED and exited.reason == "script ended"
    assert parent.finishing is not None and parent.finishing.reason == "script ended"
    assert [(e.topic, e.type) for e in parent.finishing.published] == [("Buzzer", "std_msgs/Bool")]


def test_a_broken_pipe_reaches_the_runner_as_protocol_error(tmp_path: Path) -> None:
    parent = Parent(
        """
        import rospy
        rospy.init_node("sleeper")
        while True:
            try:
                rospy.sleep(0.1)
            except Exception:
                pass  # a student's catch-all must not swallow a lost parent
        """,
        tmp_path,
    )
    assert isinstance(parent.next(), Yield)
    parent.link.to_child.put(b"")
    try:
        parent.next()
    except ProtocolError as error:
        assert "closed" in str(error)
    else:
        raise AssertionError("run_node should have raised ProtocolError")


def test_a_deferred_module_loads_between_one_pair_of_library_loading_frames(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A module of host.DEFERRED_MODULES runs at its first use, between LibraryLoading(done=
    False) and (done=True), so the parent stops the step's clock for the load; another deferred
    module its code uses loads inside the same pair."""
    package = tmp_path / "lib" / "deferpkg2"
    package.mkdir(parents=True)
    (package / "__init__.py").write_text("")
    (package / "inner.py").write_text("VALUE = 41\n")
    (package / "outer.py").write_text("import deferpkg2.inner as inner\nVALUE = inner.VALUE + 1\n")
    monkeypatch.syspath_prepend(str(tmp_path / "lib"))
    monkeypatch.setattr(host, "DEFERRED_MODULES", ("deferpkg2.outer", "deferpkg2.inner"))
    workdir = tmp_path / "work"
    workdir.mkdir()
    try:
        parent = Parent(
            """
            import sys
            import rospy
            import deferpkg2.outer as outer
            rospy.init_node("user")
            ran_at_import = "deferpkg2.inner" in sys.modules
            rospy.sleep(0.1)
            with open("seen.txt", "w") as f:
                f.write(f"{ran_at_import} {outer.VALUE}")
            """,
            workdir,
        )
        first = parent.next()
        assert isinstance(first, Yield) and parent.library_loads == []  # bound, not run
        exited = parent.wake(0.1)
        assert isinstance(exited, Exited) and exited.outcome is Outcome.FINISHED, exited
        assert parent.library_loads == [False, True]
        assert (workdir / "seen.txt").read_text() == "False 42"
    finally:
        for name in ("deferpkg2.outer", "deferpkg2.inner", "deferpkg2"):
            sys.modules.pop(name, None)
