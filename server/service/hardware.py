"""The lab bench as the service sees it: robots that connected (over rosserial, for now),
matched to their inventory entries, each with a fair queue, handed to runs as a `RobotLink`.

    hub = HardwareHub(store, settings); hub.start()     # listens on settings.rosserial_port
    link = hub.link("crowbot-1")                         # a connected robot, or None
    hub.queue("crowbot-1").join(user_id, now)            # server/hardware/queue.py
    hub.listen(run_service.command)                      # told when a run's slot is over

A robot is matched by the address it connects from (its inventory entry's `address`, the
CrowBot's WiFi IP): ros_lib has no authentication, so an address no entry has gets no session
(closed at accept, see server/hardware/rosserial/admission.py), and a second connection for a
robot that is in a run is refused so it cannot end that run or feed it readings (the instructor
sees the conflict in the robot's connection state); an idle robot's reconnection replaces its
old session (a rebooted robot comes back), and the old connection is put at rest and closed at
once: left open, its readings went on reaching the robot's later runs (issue 33, finding 14).
Only the connection a link was made for feeds it. A robot must offer the topics of its kind (the
simulated robot's names and types); a mismatch is kept as a problem the instructor sees. The
rosserial thread hands each message to the link's inbox (`RosserialLink`,
server/hardware/rosserial/link.py; bounded: latest values win when a run is not reading).

The hub knows no run service: when a run's time slot is over it sends a typed `Stop` to the
listeners it was given (the run service subscribes when it is made), so neither points at the
other.
"""

from __future__ import annotations

import contextlib
import logging
import threading
import time
from collections.abc import Callable

from server.hardware.health import LinkHealth, RobotHealth, assess
from server.hardware.queue import RobotQueue, SlotState
from server.hardware.rosserial import Refusal, RobotConnection, RosserialHandler, RosserialServer
from server.hardware.rosserial.link import RosserialLink, link_lost
from server.hardware.rosserial.messages import LogLevel
from server.runs.commands import RunCommand, Stop
from server.sim.registry import get_robot
from server.store import robots as inventory
from server.store.db import Store

log = logging.getLogger("robodojo.hardware")
QUEUE_TICK_S = 1.0  # [s] slots not started in time pass on, runs past their slot stop
SLOT_OVER = "the robot's time slot is over"  # the reason a run past its slot stops with
# (run_id, command): a run on a robot must be told something (server/runs/commands.py)
RunCommandListener = Callable[[str, RunCommand], object]


class HardwareHub(RosserialHandler):
    def __init__(self, store: Store, settings) -> None:
        self.store = store
        self.settings = settings
        self._links: dict[str, RosserialLink] = {}
        self._by_connection: dict[str, str] = {}  # connection id -> robot name
        self._problems: dict[str, list[str]] = {}  # robot name or address -> sentences
        self._conflicts: dict[str, str] = {}  # robot name -> the last refused second connection
        self._queues: dict[str, RobotQueue] = {}
        self._lock = threading.Lock()
        self.server: RosserialServer | None = None
        self.listen_error = ""
        self._listeners: list[RunCommandListener] = []  # told to stop runs past their slot
        self._closing = threading.Event()
        self._ticker = threading.Thread(target=self._tick_queues, name="robot-queues", daemon=True)

    # ------------------------------------------------------------------ lifecycle
    def start(self) -> None:
        self._ticker.start()
        port = self.settings.rosserial_port
        if port is None or port < 0:
            self.listen_error = "rosserial is switched off (--rosserial-port -1)"
            return
        host = self.settings.rosserial_bind_host
        server = RosserialServer(self, host=host, port=port)
        try:
            server.start()
        except OSError as error:  # a busy port must not stop the lab: simulation goes on
            self.listen_error = f"{error}; real CrowBots cannot connect"
            log.warning("%s", self.listen_error)
            return
        self.server = server
        log.info("rosserial: CrowBots connect to %s:%d", host, server.port)
        if host in ("127.0.0.1", "::1", "localhost"):
            log.warning(
                "rosserial listens on %s only: robots on the network cannot connect; pass "
                "--rosserial-host with the address of the robots' VLAN/SSID interface",
                host,
            )
        elif host in ("0.0.0.0", "::", ""):
            log.info(
                "rosserial listens on all interfaces: only registered robot addresses get a "
                "session, but addresses can be spoofed; pass --rosserial-host with the robots' "
                "VLAN/SSID interface or firewall port %d to their subnet (README, 'Network "
                "isolation for the bench')",
                server.port,
            )

    def _tick_queues(self) -> None:
        while not self._closing.wait(QUEUE_TICK_S):
            with self._lock:
                queues = list(self._queues.values())
            for queue in queues:
                for run_id in queue.tick(time.monotonic()):
                    self._tell(run_id, Stop(SLOT_OVER))

    def listen(self, listener: RunCommandListener) -> None:
        """Call `listener(run_id, command)` when a run on a robot must be told something (its
        time slot is over: a Stop). The run service listens; the hub knows no service."""
        self._listeners.append(listener)

    def _tell(self, run_id: str, command: RunCommand) -> None:
        for listener in list(self._listeners):
            try:
                listener(run_id, command)
            except Exception:  # one listener's failure must not keep the queues from ticking
                log.exception("hardware: telling run %s to %s failed", run_id, command.op)

    def stop(self) -> None:
        self._closing.set()
        if self.server is not None:
            self.server.stop()
        with self._lock:
            links = list(self._links.values())
        for link in links:
            close = getattr(link, "close", None)  # serial links own their port
            if close is not None:
                with contextlib.suppress(Exception):
                    close()

    @property
    def port(self) -> int | None:
        return self.server.port if self.server is not None else None

    # ------------------------------------------------------------------ rosserial thread
    def admit(self, host: str) -> Refusal | None:
        with self.store.session() as db:
            entry = inventory.by_address(db, "rosserial", host)
            name = entry.name if entry is not None else None
        if name is None:
            return Refusal(
                f"{host} is no registered robot's address: register it (POST /api/admin/robots "
                "with this address) if it is one of the bench's robots"
            )
        return self._refuse_if_in_run(name, host)

    def _in_run(self, name: str) -> bool:
        with self._lock:
            queue = self._queues.get(name)
            link = self._links.get(name)
        running = queue is not None and any(p.state is SlotState.RUNNING for p in queue.places)
        return running and link is not None and link.connected

    def _refuse_if_in_run(self, name: str, host: str) -> Refusal | None:
        """A robot in a run keeps its session: a newcomer from its address would end the run
        and, if it is not the robot, feed the next run its readings."""
        if not self._in_run(name):
            return None
        sentence = (
            f"a second connection from {host} was refused while {name} is in a run "
            f"(at {time.strftime('%H:%M:%S')}); if the robot rebooted, it is admitted once "
            "the run ends or its old connection times out"
        )
        with self._lock:
            self._conflicts[name] = sentence
        return Refusal(sentence, backoff=False)

    def on_robot_connected(self, robot: RobotConnection) -> None:
        address = robot.peer[0]
        with self.store.session() as db:
            entry = inventory.by_address(db, "rosserial", address)
            known = entry is not None
            name, kind = (entry.name, entry.kind) if known else (address, None)
        problems: list[str] = []  # the session's own are read live (RosserialLink.problems)
        if not known:
            problems.append(
                f"a robot connected from {address}, which no inventory entry has: register it "
                "(POST /api/admin/robots with this address) and reconnect it"
            )
        else:
            offered = {t.name: t.message_type for t in robot.topics.values()}
            for topic in get_robot(kind).topics():
                if offered.get(topic.name) != topic.type_name:
                    problems.append(
                        f"{name} does not offer topic '{topic.name}' [{topic.type_name}] that a "
                        f"{kind} has (it offers: {', '.join(sorted(offered)) or 'nothing'})"
                    )
        if known and (refusal := self._refuse_if_in_run(name, address)) is not None:
            log.warning("hardware: %s", refusal.reason)  # it was admitted before the run began
            robot.stop()
            return
        old = None
        with self._lock:
            # An unregistered robot has no link to read its session's problems from later.
            self._problems[name] = problems if known else problems + list(robot.problems)
            self._conflicts.pop(name, None)
            if known:
                old = self._links.get(name)
                self._links[name] = RosserialLink(robot, name)
                self._by_connection[robot.id] = name
                if isinstance(old, RosserialLink):
                    self._by_connection.pop(old.connection.id, None)
        if isinstance(old, RosserialLink) and old.connection is not robot:
            old.lose(
                link_lost(f"{name} connected again from {address}, which replaced this connection")
            )
            # At rest and closed now, outside the lock (its close comes back through
            # on_robot_disconnected): nothing the old connection sends is read any more.
            old.connection.stop()
            log.info("hardware: %s: the new connection replaced %s", name, old.connection.id)
        for problem in problems:
            log.warning("hardware: %s", problem)

    def on_robot_disconnected(self, robot: RobotConnection, reason: str) -> None:
        with self._lock:
            name = self._by_connection.pop(robot.id, None)
            link = self._links.get(name) if name else None
            if link is None or getattr(link, "connection", None) is not robot:
                link = None  # another connection's link (it replaced this one): not ours to end
            else:
                del self._links[name]
        if link is not None:
            link.lose(link_lost(reason))
            log.info("hardware: %s disconnected (%s)", name, reason)

    def on_message(self, robot: RobotConnection, topic: str, message) -> None:
        link = self._link_of(robot)
        if link is not None:
            link.push(topic, message)

    def on_log(self, robot: RobotConnection, level: LogLevel, line: str) -> None:
        link = self._link_of(robot)
        if link is not None:
            link.log(f"[{level.name.lower()}] {line}")

    def _link_of(self, robot: RobotConnection) -> RosserialLink | None:
        """The link made for this very connection, or None: a replaced connection's messages
        must never reach the link (and the runs) of the one that replaced it."""
        name = self._by_connection.get(robot.id)
        link = self._links.get(name) if name else None
        return link if isinstance(link, RosserialLink) and link.connection is robot else None

    # ------------------------------------------------------------------ the service's side
    def link(self, name: str):
        """A connected robot by inventory name: a rosserial robot that connected to us, or a
        serial (Create/Roomba) base opened now; None (and a problem noted) otherwise."""
        with self._lock:
            link = self._links.get(name)
        if link is not None and link.connected:
            return link
        with self.store.session() as db:
            entry = inventory.by_name(db, name)
            serial = entry is not None and entry.transport == "create_oi"
            port, baud = (entry.address, entry.baud) if serial else (None, None)
        if not serial:
            return None
        return self._open_serial(name, port, baud)

    def _open_serial(self, name: str, port: str, baud: int | None):
        from server.hardware.create.link import CreateLink
        from server.hardware.create.port import CreateError

        link = CreateLink(port, baud)
        try:
            link.open()
        except (CreateError, OSError, ValueError) as error:
            with self._lock:
                self._problems[name] = [f"{name}: {error}"]
            log.warning("hardware: %s: %s", name, error)
            return None
        with self._lock:
            old = self._links.get(name)
            self._links[name] = link
            self._problems[name] = []
        if old is not None:
            with contextlib.suppress(Exception):
                old.close()
        return link

    def robots(self) -> list[str]:
        """The robots this hub knows now: connected, or with a queue (a bench worker publishes
        their health, server/workers/bench.py)."""
        with self._lock:
            return sorted(set(self._links) | set(self._queues))

    def queue(self, name: str) -> RobotQueue:
        with self._lock:
            queue = self._queues.get(name)
            if queue is None:
                queue = self._queues[name] = RobotQueue(
                    name,
                    slot_s=self.settings.hardware_slot_s,
                    start_within_s=self.settings.hardware_start_within_s,
                )
            return queue

    def health(self, name: str) -> RobotHealth:
        """Connected / syncing / stale / disconnected, last heard, problems (health.py): from
        what the link knows now, so a clean handshake clears what it explains."""
        with self._lock:
            link = self._links.get(name)
            conflict = self._conflicts.get(name)
            problems = list(self._problems.get(name) or [])
        if link is None or not link.connected:
            return assess(None)
        problems += getattr(link, "problems", [])
        if conflict:
            problems.append(conflict)
        report = getattr(link, "health", None)
        return assess(report() if report is not None else LinkHealth(True, None), problems)

    def connection_state(self, name: str) -> str:
        return self.health(name).sentence

    def problems(self) -> dict[str, list[str]]:
        with self._lock:
            found = {name: list(p) for name, p in self._problems.items() if p}
            links = list(self._links.items())
        for name, link in links:
            if link.connected and (live := getattr(link, "problems", [])):
                found[name] = found.get(name, []) + live
        return found
