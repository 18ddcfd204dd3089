"""Every limit of the rosserial host in one table, with the reason for each value.

A CrowBot (000_32b6074bbd2115c3.txt, Fig. 6) runs ros_lib with 512-byte buffers and publishes four
small topics; the values below leave generous headroom for that robot and bound what any other
client - a garbage flood, a half-open WiFi link, a firmware with a bug - can cost the server.
Tests shrink the timeouts with ``dataclasses.replace(DEFAULT_LIMITS, ...)``.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True, slots=True)
class RosserialLimits:
    """Per-connection and per-server limits; see ``DEFAULT_LIMITS`` for the why of each value."""

    max_payload_bytes: int
    read_buffer_bytes: int
    max_bytes_per_s: int
    max_frames_per_s: int
    max_write_buffer_bytes: int
    socket_send_buffer_bytes: int
    max_outbox_bytes: int
    max_connections: int
    max_problems: int
    frame_timeout_s: float
    settle_s: float
    negotiation_timeout_s: float
    sync_timeout_s: float
    idle_timeout_s: float
    request_topics_interval_s: float
    poll_interval_s: float
    listen_beat_s: float
    handshake_timeout_s: float
    max_pending_per_address: int
    refusals_before_backoff: int
    refusal_window_s: float
    backoff_s: float
    refusal_log_interval_s: float
    max_tracked_addresses: int

    def __post_init__(self) -> None:
        for name in self.__slots__:
            value = getattr(self, name)
            if not value > 0:
                raise ValueError(f"RosserialLimits.{name} must be positive, got {value!r}")


DEFAULT_LIMITS = RosserialLimits(
    # [bytes] largest frame payload accepted. ros_lib's default buffers are 512 bytes (the CrowBot's
    # serial_node log: "publish buffer size is 512 bytes"); 4x that admits boards built with bigger
    # buffers, and bounds the parser's buffer (a frame is held until complete) to ~2 KiB.
    max_payload_bytes=2048,
    # [bytes] one socket read. The connection reads into a fixed buffer of this size, so a flood
    # never makes the server allocate more than this per connection and read.
    read_buffer_bytes=4096,
    # [bytes/s] reading pauses for the rest of the second past this. A CrowBot at 20 Hz sends
    # ~3 KB/s (100 Hz: ~17 KB/s); 128 KB/s keeps a garbage flood to a bounded share of one core
    # (the worst crafted input costs the parser ~1.5 s per MB).
    max_bytes_per_s=128 * 1024,
    # [frames/s] topic data frames beyond this, within one second, are dropped and counted. A
    # CrowBot at 20 Hz sends 80 (4 topics); 1000 admits a 100 Hz loop with room to spare.
    max_frames_per_s=1000,
    # [bytes] unsent data queued for a robot that does not read (half-open link). Commands wait
    # (latest wins, server.py) while anything is unsent; past this even a stop is dropped and
    # counted: a stale Control is worse than none.
    max_write_buffer_bytes=16 * 1024,
    # [bytes] the kernel's send buffer per robot (SO_SNDBUF; Linux doubles it). Without it Linux
    # grows the buffer to megabytes on a fast link, where a stalled robot's commands would queue
    # for seconds; commands are a few kB/s, so a small buffer costs nothing and stale commands
    # are dropped (and counted) here instead of delivered late.
    socket_send_buffer_bytes=16 * 1024,
    # [bytes] frames a session queues between two drains by its connection (the server drains
    # after every call, so this only bounds a caller that forgets).
    max_outbox_bytes=64 * 1024,
    # [connections] robots on one bench at once; more are refused at accept.
    max_connections=16,
    # [sentences] problems kept per session for the instructor (duplicates are kept once).
    max_problems=32,
    # [s] a frame started but not completed within this is abandoned and the bytes after its sync
    # flag are scanned again. rosserial_python waits up to its 5 s port timeout; WiFi stalls are
    # shorter than 1 s, and a bogus header inside garbage must not hold good frames for long.
    frame_timeout_s=1.0,
    # [s] negotiation is over when no TopicInfo has arrived for this long (ros_lib sends all of
    # them back to back in one negotiateTopics() call) or at the first topic data frame.
    settle_s=0.5,
    # [s] a connection that advertises no topic at all within this is closed (not a rosserial
    # client, or one from another ROS release that never answers the topic request).
    negotiation_timeout_s=45.0,
    # [s] without a time request for this long the sync is lost and topics are requested again:
    # rosserial_python's 3 x its 5 s timeout (SerialClient.run). ros_lib asks every 2.5 s.
    sync_timeout_s=15.0,
    # [s] a connection silent this long is closed: two sync timeouts, so a robot that lost sync
    # had one topic request to answer (powered off, out of WiFi range, half-open connection).
    idle_timeout_s=30.0,
    # [s] frames on unknown topic ids make the host request topics again (as rosserial_python
    # does), at most this often, so a flood of them does not become a flood of requests.
    request_topics_interval_s=1.0,
    # [s] how often timers (sync, silence, frame timeout) are checked for every connection.
    poll_interval_s=0.1,
    # [s] how often the rosserial thread notes that it is listening (`listened_until_s`): a run's
    # silence watchdog counts a robot silent only up to the last beat, so a host too busy to read
    # its sockets does not blame the robot; 20 ms keeps the watchdog's 0.3 s bound within 40 ms.
    listen_beat_s=0.02,
    # ---- admission (who gets a session at all; ros_lib has no authentication, see README)
    # [s] a connection that has not finished the rosserial handshake (topics advertised and
    # settled: READY) within this is closed, so sockets that connect and say nothing cannot hold
    # a slot. ros_lib answers the topic request within milliseconds of its next spinOnce(); 10 s
    # leaves room for a WiFi stall and a firmware still running its setup().
    handshake_timeout_s=10.0,
    # [connections] handshakes in progress from one address. A further one closes the oldest:
    # a rebooted robot's new connection is the live one, and idle sockets from one address
    # cannot fill max_connections.
    max_pending_per_address=2,
    # [refusals] an address refused this often within refusal_window_s is backed off: refused
    # for backoff_s without a lookup or a log line. ros_lib retries about once a second, so a
    # mistyped address in the inventory is still reported every minute.
    refusals_before_backoff=5,
    # [s] the window in which refusals are counted.
    refusal_window_s=10.0,
    # [s] how long a backed-off address is refused outright (only unregistered addresses are
    # backed off; a robot refused while it is in a run is not, so it comes back when the run ends).
    backoff_s=30.0,
    # [s] one log line per refused address per this interval, so a flood does not fill the log.
    refusal_log_interval_s=60.0,
    # [addresses] refused addresses remembered for back-off and logging; the oldest are forgotten
    # past this, so a sweep of spoofed addresses cannot grow the server's memory.
    max_tracked_addresses=4096,
)
