"""The recording of one run: every topic in an MCAP file, plus the nodes' logs, their artifacts
and JSON documents such as the metrics.

Layout of ``out_dir``::

    recording.mcap               every message, one channel per topic ("/scan")
    metadata.yaml                a ROS 2 run's bag metadata, as rosbag2 writes it
    logs/<node>.log              what each node printed, appended as it arrives
    artifacts/<node>/<name>      files a node saved
    <name>.json                  write_json("metrics", ...) -> metrics.json

The MCAP file of a ROS 1 run uses the ``ros1`` profile: each schema has encoding ``ros1msg``, the
type name as its name and genmsg's full concatenated definition as its data, and each channel has
message encoding ``ros1``, so Foxglove decodes the messages without knowing our types. A ROS 2
run's (``profile="ros2"``) is what ``ros2 bag record`` writes with the MCAP storage plugin:
``ros2msg`` schemas, ``cdr`` channels with rosbag2's channel metadata, a ``rosbag2`` metadata
record and ``metadata.yaml`` beside it (server/runs/rosbag2.py). A metadata record named ``run``
carries the run id and whatever run information the caller passes.

Off the hot path: ``record()`` appends a tuple to an in-memory list under a lock and returns
(about a microsecond); a writer thread swaps the list out in batches and writes it (schemas,
channels, chunk compression, disk). Log lines travel the same way.

Backpressure, not loss: the bytes waiting to be written (payloads plus a fixed per-message
overhead, including the batch the writer is busy with) are bounded by ``max_buffer_bytes``.
When the writer falls that far behind, ``record()`` blocks until it has caught up. A run then
slows down instead of eating memory or silently dropping messages; in lockstep that only
stretches wall time, in realtime it shows as latency, which is honest about a disk that cannot
keep up.

Failure is contained: an error while writing (disk full, a file that cannot be created, bad
data) never raises into the caller. The recorder turns ``FAILED``, says why in ``error``
("recording failed: [Errno 28] No space left on device"), drops what is buffered and makes
``record()`` a cheap no-op; ``close()`` still returns.

Lifecycle (checked): RECORDING -> CLOSED on ``close()``, RECORDING -> FAILED on a write error
(final; ``close()`` keeps it). ``record()`` after ``close()`` is a programming error and raises;
``write_artifacts``/``write_json`` are synchronous, meant for the end of a run, before
``close()``.
"""

from __future__ import annotations

import contextlib
import importlib.util
import json
import logging
import math
import os
import threading
import time
from collections.abc import Iterable, Mapping
from enum import StrEnum
from pathlib import Path
from typing import IO, Any

from mcap.writer import CompressionType, Writer

from sandbox.msgs import Message, get_message_class
from server.runs import rosbag2
from server.runs.safe_paths import inside, safe_name, safe_relative_path

log = logging.getLogger(__name__)

RECORDING_FILE = "recording.mcap"
LOGS_DIR = "logs"
ARTIFACTS_DIR = "artifacts"

# Limits: value [unit] and why.
DEFAULT_MAX_BUFFER_BYTES = 64 * 1024 * 1024  # [B] ~35k LiDAR scans: only a stalled disk gets here
_ENTRY_OVERHEAD_BYTES = 128  # [B] a tuple + int + topic ref in CPython; bounds tiny messages too
_WRITER_WAKE_BYTES = 1024 * 1024  # [B] wake the writer early once this much waits (one chunk)
# [s] otherwise the writer drains what has gathered this often. Each wake takes the GIL from
# the realtime scheduler: at 50 ms, fifty runs' writers woke a worker 1,000 times a second
# (a tenth of its interpreter time, issue 16); a quarter second of messages is a few kB.
_WRITER_POLL_S = 0.25
CHUNK_FLUSH_S = 1.0  # [s] chunks are closed at least this often: what a crash can lose
_CLOSE_TIMEOUT_S = 60.0  # [s] a writer that cannot finish in this long is declared failed


class RecorderState(StrEnum):
    RECORDING = "recording"
    CLOSED = "closed"
    FAILED = "failed"


class RecorderClosedError(RuntimeError):
    """The recorder was used after ``close()``."""


def mcap_topic(name: str) -> str:
    """The MCAP/ROS topic name of a bus topic: ``scan`` -> ``/scan`` (ROS tools expect the
    leading slash)."""
    return name if name.startswith("/") else "/" + name


def json_safe(value: Any) -> Any:
    """Non-finite floats become null: JSON has no NaN or Infinity."""
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, Mapping):
        return {str(key): json_safe(item) for key, item in value.items()}
    if isinstance(value, list | tuple):
        return [json_safe(item) for item in value]
    return value


def _describe(error: BaseException) -> str:
    if isinstance(error, OSError):
        return str(error)
    kind = type(error)
    name = kind.__name__ if kind.__module__ == "builtins" else f"{kind.__module__}.{kind.__name__}"
    return f"{name}: {error}"


def _default_compression() -> CompressionType:
    if importlib.util.find_spec("zstandard") is not None:
        return CompressionType.ZSTD
    return CompressionType.NONE


class Recorder:
    """Writes one run's recording into `out_dir`; see the module docstring for the contract.

    `metadata` (str -> str) goes into the MCAP ``run`` metadata record next to the run id.
    """

    def __init__(
        self,
        out_dir: Path,
        run_id: str,
        *,
        metadata: Mapping[str, str] | None = None,
        max_buffer_bytes: int = DEFAULT_MAX_BUFFER_BYTES,
        compression: CompressionType | None = None,
        profile: str = "ros1",
    ) -> None:
        if profile not in ("ros1", "ros2"):
            raise ValueError(f"profile must be 'ros1' or 'ros2', got {profile!r}")
        if not isinstance(max_buffer_bytes, int) or max_buffer_bytes <= 0:
            raise ValueError(f"max_buffer_bytes must be a positive int, got {max_buffer_bytes!r}")
        run_metadata = {"run_id": str(run_id)}
        for key, value in (metadata or {}).items():
            if not isinstance(key, str) or not isinstance(value, str):
                raise TypeError(f"metadata must map str to str; {key!r}: {value!r} is not")
            run_metadata[key] = value
        self.out_dir = Path(out_dir)
        self.run_id = str(run_id)
        self.profile = profile
        self._ros2 = profile == "ros2"
        self.recording_path = self.out_dir / RECORDING_FILE
        self.max_buffer_bytes = max_buffer_bytes
        self._wake_bytes = min(_WRITER_WAKE_BYTES, max(1, max_buffer_bytes // 2))
        self._lock = threading.Lock()
        self._changed = threading.Condition(self._lock)
        # Shared with the writer thread, guarded by _lock.
        self._buffer: list[tuple[tuple[str, str], int, bytes]] = []  # ((topic, type), t, data)
        self._buffered_bytes = 0
        self._pending_topics: list[tuple[str, str, type[Message]]] = []
        self._pending_logs: dict[str, list[str]] = {}
        self._accepting = True
        self._state = RecorderState.RECORDING
        self.error: str | None = None
        # Caller side.
        self._topic_types: dict[str, str] = {}  # topic -> its first type
        self._known: set[tuple[str, str]] = set()  # (topic, type) declared
        self._paths: dict[str, str] = {}
        self._closed_paths: dict[str, str] | None = None
        # Writer side.
        self._channels: dict[tuple[str, str], int] = {}
        self._channels_by_mcap_topic: dict[tuple[str, str], int] = {}
        self._channel_counts: dict[int, int] = {}  # channel id -> messages written
        self._channel_topics: list[tuple[int, str, str]] = []  # (id, MCAP topic, type)
        self._time_range: list[int] = []  # [first, last] log time written [ns]
        self._schemas: dict[str, int] = {}
        self._log_files: dict[str, IO[str]] = {}
        self._file: IO[bytes] | None = None
        self._writer: Writer | None = None
        self._last_chunk_flush = time.monotonic()
        self._thread: threading.Thread | None = None
        try:
            self.out_dir.mkdir(parents=True, exist_ok=True)
            self._file = open(self.recording_path, "wb")  # noqa: SIM115  # closed by the writer
            self._writer = Writer(self._file, compression=compression or _default_compression())
            self._writer.start(profile=profile)
            self._writer.add_metadata("run", run_metadata)
        except Exception as error:  # a recorder never raises a write error
            self._fail(error)
            self._close_files()
            return
        self._thread = threading.Thread(
            target=self._write_loop, name=f"recorder-{self.run_id}", daemon=True
        )
        self._thread.start()

    # ----------------------------------------------------------------------------- state
    @property
    def state(self) -> RecorderState:
        return self._state

    def _fail(self, error: BaseException) -> None:
        """Enter FAILED with a sentence; the writer thread notices and closes its files."""
        message = f"recording failed: {_describe(error)}"
        with self._lock:
            if self.error is None:
                self.error = message
            self._state = RecorderState.FAILED
            self._accepting = False
            self._buffer = []
            self._buffered_bytes = 0
            self._pending_logs = {}
            self._changed.notify_all()
        log.warning("run %s: %s", self.run_id, message)

    def _close_files(self) -> None:
        for handle in [*self._log_files.values(), self._file]:
            if handle is not None:
                with contextlib.suppress(OSError):
                    handle.close()
        self._log_files = {}

    def _check_open(self, what: str) -> bool:
        """True to go ahead; False after a failure (no-op); raises after close()."""
        if self._state is RecorderState.FAILED:
            return False
        if self._closed_paths is not None:
            raise RecorderClosedError(f"{what} after close(): the recording is already finished")
        return True

    # ----------------------------------------------------------------------------- topics
    def add_topic(self, name: str, type_name: str) -> None:
        """Declare a topic so its channel exists even before (or without) a message.

        Idempotent; a second type on the same topic is refused, as ROS 1 refuses it (a ROS 2
        recording gives it a channel of its own: ROS 2 lets a topic carry several types)."""
        if not isinstance(name, str) or not name.strip("/"):
            raise ValueError(f"topic name must be a non-empty string, got {name!r}")
        cls = get_message_class(type_name)  # unknown type: a sentence listing the known ones
        if not self._check_open("add_topic()"):
            return
        topic = mcap_topic(name)
        with self._lock:
            for known_name, known_type in self._topic_types.items():
                if mcap_topic(known_name) == topic and known_type != type_name and not self._ros2:
                    raise ValueError(
                        f"topic '{topic}' is recorded as {known_type}; it cannot carry "
                        f"{type_name} too (use another topic name)"
                    )
            if (name, type_name) not in self._known:
                self._topic_types.setdefault(name, type_name)
                self._known.add((name, type_name))
                self._pending_topics.append((name, type_name, cls))

    # ----------------------------------------------------------------------------- hot path
    def record(self, topic: str, type_name: str, log_time_ns: int, data: bytes) -> None:
        """Queue one serialized message (ROS 1 bytes, or CDR in a ROS 2 recording) published
        at run time `log_time_ns` [ns].

        Returns at once unless the writer is `max_buffer_bytes` behind (then it waits); a no-op
        once the recorder has failed."""
        if self._state is RecorderState.FAILED:
            return
        key = (topic, type_name)
        if key not in self._known:
            self.add_topic(topic, type_name)
        if type(data) is not bytes:
            raise TypeError(f"record() needs the serialized bytes, got {type(data).__name__}")
        size = len(data) + _ENTRY_OVERHEAD_BYTES
        with self._lock:
            if not self._accepting:
                if self._state is RecorderState.FAILED:
                    return
                raise RecorderClosedError("record() after close(): the recording is finished")
            if self._buffered_bytes and self._buffered_bytes + size > self.max_buffer_bytes:
                self._wait_for_room(size)
                if not self._accepting:
                    return  # failed or closed while we waited
            self._buffer.append((key, log_time_ns, data))
            self._buffered_bytes += size
            if self._buffered_bytes >= self._wake_bytes:
                self._changed.notify_all()

    def _wait_for_room(self, size: int) -> None:
        """Backpressure (lock held): block until the writer has made room for `size` bytes. A
        message larger than the whole budget waits for an empty buffer, then goes in alone."""
        self._changed.notify_all()
        while (
            self._accepting
            and self._buffered_bytes
            and self._buffered_bytes + size > self.max_buffer_bytes
        ):
            self._changed.wait()

    def record_message(self, topic: str, log_time_ns: int, message: Message) -> None:
        """``record()`` for a message object (serialized here, on the caller's thread)."""
        if self._state is RecorderState.FAILED:
            return
        self.record(topic, message._type, log_time_ns, message.serialize())

    def write_log(self, node: str, lines: Iterable[str]) -> None:
        """Append `lines` (without or with a trailing newline) to ``logs/<node>.log``; written by
        the writer thread like the messages."""
        if not self._check_open("write_log()"):
            return
        texts = [line if line.endswith("\n") else line + "\n" for line in lines]
        size = sum(len(text) for text in texts) + _ENTRY_OVERHEAD_BYTES
        with self._lock:
            if not self._accepting:
                return
            if self._buffered_bytes and self._buffered_bytes + size > self.max_buffer_bytes:
                self._wait_for_room(size)
                if not self._accepting:
                    return
            self._pending_logs.setdefault(safe_name(node), []).extend(texts)
            self._buffered_bytes += size

    # ----------------------------------------------------------------------------- end of run
    def write_artifacts(self, node: str, artifacts: Iterable[tuple[str, bytes]]) -> list[Path]:
        """Write files a node saved to ``artifacts/<node>/<name>`` (names sanitized: they stay
        inside ``out_dir`` whatever they contain). Synchronous: call it at the end of a run."""
        if not self._check_open("write_artifacts()"):
            return []
        files = []
        for name, data in artifacts:
            if not isinstance(data, bytes | bytearray | memoryview):
                raise TypeError(f"artifact {name!r} must be bytes, got {type(data).__name__}")
            files.append((str(name), bytes(data)))
        root = self.out_dir / ARTIFACTS_DIR
        written = []
        try:
            node_dir = inside(root, Path(safe_name(node)))
            for name, data in files:
                target = inside(node_dir, safe_relative_path(name))
                target.parent.mkdir(parents=True, exist_ok=True)
                target.write_bytes(data)
                written.append(target)
        except (OSError, ValueError) as error:  # a recorder never raises a write error
            self._fail(error)
            return written
        if written:
            self._paths["artifacts"] = str(root)
        return written

    def write_json(self, name: str, document: Any) -> Path | None:
        """Write `document` to ``<name>.json`` (e.g. "metrics"), replacing it atomically; NaN
        and infinities become null. Synchronous: call it at the end of a run."""
        if not self._check_open("write_json()"):
            return None
        stem = safe_name(name.removesuffix(".json"))
        target = self.out_dir / f"{stem}.json"
        temporary = self.out_dir / f".{stem}.json.tmp"
        try:
            text = json.dumps(json_safe(document), indent=2, allow_nan=False, default=str)
            temporary.write_text(text + "\n", encoding="utf-8")
            os.replace(temporary, target)
        except Exception as error:  # a recorder never raises a write error
            self._fail(error)
            return None
        self._paths[stem] = str(target)
        return target

    def close(self, timeout_s: float = _CLOSE_TIMEOUT_S) -> dict[str, str]:
        """Flush everything, finish the MCAP file and return the paths written ("recording",
        "logs", "artifacts", one per JSON document). Safe to call twice; never raises a write
        error (see ``error``)."""
        if self._closed_paths is not None:
            return dict(self._closed_paths)
        with self._lock:
            self._accepting = False
            self._changed.notify_all()
        if self._thread is not None:
            self._thread.join(timeout_s)
            if self._thread.is_alive():
                self._fail(TimeoutError(f"the writer did not finish within {timeout_s:g} s"))
        if self._state is not RecorderState.FAILED:
            self._state = RecorderState.CLOSED
            self._paths = {"recording": str(self.recording_path), **self._paths}
        self._closed_paths = dict(self._paths)
        return dict(self._closed_paths)

    def __enter__(self) -> Recorder:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()

    # ----------------------------------------------------------------------------- writer
    def _write_loop(self) -> None:
        try:
            while True:
                with self._lock:
                    if self._accepting and self._buffered_bytes < self._wake_bytes:
                        self._changed.wait(_WRITER_POLL_S)
                    if self._state is RecorderState.FAILED:
                        return
                    batch, self._buffer = self._buffer, []
                    topics, self._pending_topics = self._pending_topics, []
                    logs, self._pending_logs = self._pending_logs, {}
                    taken_bytes = self._buffered_bytes
                    last_pass = not self._accepting
                self._write_topics(topics)
                self._write_batch(batch)
                self._write_logs(logs)
                with self._lock:
                    # Counted until written, so the bound covers the batch in flight too.
                    self._buffered_bytes = max(0, self._buffered_bytes - taken_bytes)
                    self._changed.notify_all()
                if last_pass:
                    break
            assert self._writer is not None
            if self._ros2:
                self._write_rosbag2_metadata()
            self._writer.finish()
        except Exception as error:  # contained: the run goes on without us
            self._fail(error)
        finally:
            self._close_files()

    def _write_topics(self, topics: list[tuple[str, str, type[Message]]]) -> None:
        writer = self._writer
        assert writer is not None
        for name, type_name, cls in topics:
            topic = mcap_topic(name)
            channel_id = self._channels_by_mcap_topic.get((topic, cls._type))
            if channel_id is None:
                schema_id = self._schemas.get(cls._type)
                if schema_id is None:
                    schema_id = writer.register_schema(
                        name=cls._type,
                        encoding=cls._schema_encoding,  # ros1msg or ros2msg
                        data=cls._full_text.encode(),
                    )
                    self._schemas[cls._type] = schema_id
                channel_id = writer.register_channel(
                    topic=topic,
                    message_encoding=cls._message_encoding,  # ros1 or cdr
                    schema_id=schema_id,
                    metadata=rosbag2.channel_metadata(topic)
                    if self._ros2
                    else {"md5sum": cls._md5sum},
                )
                self._channels_by_mcap_topic[(topic, cls._type)] = channel_id
                self._channel_topics.append((channel_id, topic, cls._type))
            self._channels[(name, type_name)] = channel_id

    def _write_batch(self, batch: list[tuple[str, int, bytes]]) -> None:
        """Write queued messages in the order they were recorded (overridable in tests)."""
        writer = self._writer
        assert writer is not None
        channels = self._channels
        for key, log_time_ns, data in batch:
            writer.add_message(
                channel_id=channels[key],
                log_time=log_time_ns,
                publish_time=log_time_ns,
                data=data,
            )
        if batch and self._ros2:  # counted for the rosbag2 metadata
            counts = self._channel_counts
            for key, _, _ in batch:
                channel_id = channels[key]
                counts[channel_id] = counts.get(channel_id, 0) + 1
            times = [log_time_ns for _, log_time_ns, _ in batch] + self._time_range
            self._time_range = [min(times), max(times)]
        if batch:
            assert self._file is not None
            now = time.monotonic()
            if now - self._last_chunk_flush >= CHUNK_FLUSH_S:
                # Close the chunk in progress: a crash of the server then loses at most the
                # last CHUNK_FLUSH_S of messages; the rest reads back (a stream reader reads
                # an MCAP file without its summary section).
                writer.flush()
                self._last_chunk_flush = now
            self._file.flush()

    def _write_rosbag2_metadata(self) -> None:
        """The bag's metadata, in the MCAP file and as metadata.yaml (server/runs/rosbag2.py)."""
        assert self._writer is not None
        start_ns, end_ns = self._time_range or [0, 0]
        topics = [
            (topic, type_name, self._channel_counts.get(channel_id, 0))
            for channel_id, topic, type_name in self._channel_topics
        ]
        metadata = rosbag2.bag_metadata(RECORDING_FILE, topics, start_ns, end_ns)
        self._writer.add_metadata(
            rosbag2.METADATA_RECORD, {"serialized_metadata": rosbag2.serialized(metadata)}
        )
        self._paths["metadata"] = str(rosbag2.write_metadata_yaml(self.out_dir, metadata))

    def _write_logs(self, logs: dict[str, list[str]]) -> None:
        if not logs:
            return
        logs_dir = self.out_dir / LOGS_DIR
        for node, texts in logs.items():
            handle = self._log_files.get(node)
            if handle is None:
                logs_dir.mkdir(parents=True, exist_ok=True)
                path = inside(logs_dir, Path(f"{node}.log"))
                handle = open(path, "a", encoding="utf-8")  # noqa: SIM115  # closed at the end
                self._log_files[node] = handle
                self._paths["logs"] = str(logs_dir)
            handle.writelines(texts)
            handle.flush()
