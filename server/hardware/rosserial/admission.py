"""Who gets a rosserial session: the handler's verdict, and back-off for refused addresses.

ros_lib (rosserial_client) has no authentication: whoever reaches the port and speaks the
protocol is a robot. The only identity a CrowBot has is the address it connects from, so the
server asks its handler (``RosserialHandler.admit``) before a session exists, closes refused
peers at once (no topic request, no slot), logs each refused address at most once per
``refusal_log_interval_s`` and backs off an address that keeps connecting. Limits are in
limits.py; the network isolation that must go with this is in README.md ("Real robots").
"""

from __future__ import annotations

import logging
from collections import OrderedDict, deque
from dataclasses import dataclass, field

from server.hardware.rosserial.limits import RosserialLimits

logger = logging.getLogger("server.hardware.rosserial.server")


@dataclass(frozen=True, slots=True)
class Refusal:
    """Why a peer gets no session, as a sentence for the log and the instructor.

    ``backoff``: count it towards the address's back-off (unregistered addresses). A registered
    robot refused for a while (its robot is in a run) is not backed off, so it is admitted as
    soon as the reason is gone."""

    reason: str
    backoff: bool = True


@dataclass(slots=True)
class _Record:
    refusals: deque[float] = field(default_factory=deque)  # [s] monotonic times in the window
    backed_off_until_s: float = 0.0
    last_logged_s: float = float("-inf")
    suppressed: int = 0  # refusals not logged since the last line


class AdmissionControl:
    """Back-off and once-a-minute logging of refused addresses; rosserial thread only."""

    def __init__(self, limits: RosserialLimits) -> None:
        self.limits = limits
        self._records: OrderedDict[str, _Record] = OrderedDict()
        self.refused = 0  # connections closed at accept, for tests and the status page

    def backed_off(self, host: str, now_s: float) -> bool:
        """True when `host` is in its back-off period (refuse it without asking the handler)."""
        record = self._records.get(host)
        if record is None or now_s >= record.backed_off_until_s:
            return False
        self.refused += 1
        self._log(host, record, now_s, "it keeps connecting after being refused")
        return True

    def refuse(self, host: str, refusal: Refusal, now_s: float) -> None:
        """Count and log a refusal; past refusals_before_backoff, back the address off."""
        self.refused += 1
        record = self._record(host)
        limits = self.limits
        if refusal.backoff:
            record.refusals.append(now_s)
            while record.refusals and now_s - record.refusals[0] > limits.refusal_window_s:
                record.refusals.popleft()
            if len(record.refusals) >= limits.refusals_before_backoff:
                record.backed_off_until_s = now_s + limits.backoff_s
                record.refusals.clear()
        self._log(host, record, now_s, refusal.reason)

    def _record(self, host: str) -> _Record:
        record = self._records.get(host)
        if record is None:
            record = self._records[host] = _Record()
            while len(self._records) > self.limits.max_tracked_addresses:
                self._records.popitem(last=False)
        else:
            self._records.move_to_end(host)
        return record

    def _log(self, host: str, record: _Record, now_s: float, reason: str) -> None:
        if now_s - record.last_logged_s < self.limits.refusal_log_interval_s:
            record.suppressed += 1
            return
        more = (
            f" ({record.suppressed} more refused since the last line)" if record.suppressed else ""
        )
        backed = (
            f"; refusing it for {self.limits.backoff_s:.0f} s"
            if now_s < record.backed_off_until_s
            else ""
        )
        logger.warning(
            "rosserial: refused a connection from %s: %s%s%s", host, reason, backed, more
        )
        record.last_logged_s, record.suppressed = now_s, 0
