"""Every setting of the web service in one place. Each can be set by an environment variable
with the `ROBODOJO_` prefix (ROBODOJO_DATABASE_URL, ROBODOJO_MAX_RUNS_TOTAL, ...) or by the
`robodojo serve` options; the defaults are the zero-setup embedded lab."""

from __future__ import annotations

from pathlib import Path

from pydantic import Field
from pydantic_settings import BaseSettings, SettingsConfigDict

KIB = 1024
MIB = 1024 * KIB
GIB = 1024 * MIB


class Settings(BaseSettings):
    model_config = SettingsConfigDict(env_prefix="ROBODOJO_", extra="ignore")

    host: str = "127.0.0.1"
    port: int = Field(8000, ge=0, le=65535)
    data: Path = Path("robodojo-data")  # SQLite file, recordings, artifacts
    database_url: str | None = None  # None: SQLite in `data`; else postgresql://...
    # How browsers reach us (behind a proxy): printed links, and an origin the CSRF and websocket
    # Origin checks accept besides the one a request came to (auth.py).
    public_url: str | None = None
    # The cluster (issue 16): with a Redis URL the web process queues runs for `robodojo worker`
    # processes (any machine; same database and data volume) and runs none itself.
    redis_url: str | None = None
    worker_processes: int = Field(0, ge=0)  # `robodojo worker`: processes; 0 = one per core
    runs_per_process: int = Field(12, ge=1)  # runs one worker process takes at once (two cores
    # of a default worker hold the lab's default max_runs_total of 24)

    # The embedded lab (no Redis) runs its runs on worker processes of this machine, one per
    # core by default: twenty realtime runs in one interpreter miss their periods. 0 = in the web
    # process's own threads (tests, a tiny machine); runs on a real robot always stay there.
    workers: int | None = Field(None, ge=0)  # None = os.cpu_count()

    # Limits that protect the lab: value and why.
    max_runs_per_student: int = Field(2, ge=1)  # two: one running, one being looked at
    max_runs_total: int = Field(24, ge=1)  # ~a class; each node is a process of ~65 MiB
    # Sandboxes: every sandbox job of a student (a run, whose nodes are a sandbox each; a Python
    # launch file being read) counts against one budget, each sandbox at its memory cap (768 MiB,
    # sandbox/limits.py): 8 launch files read at once once took 2.6 GiB beside the run limit.
    max_sandbox_jobs_per_student: int = Field(3, ge=1)  # two runs and a launch file being read
    student_sandbox_memory_bytes: int = Field(8 * GIB, ge=0)  # [B] ten sandboxes: an 8-node run
    # and a 2-node one, or two runs of 4 and a launch file; 0 = no memory budget
    max_run_duration_s: float = Field(600.0, gt=0)  # [s] ten minutes of robot time
    max_code_bytes_per_file: int = Field(256 * KIB, ge=1)  # [B] far beyond any exercise
    max_code_bytes_per_run: int = Field(1024 * KIB, ge=1)  # [B] all nodes of one run
    max_files_per_workspace: int = Field(32, ge=1)  # a package: nodes, launch, config, data
    max_data_bytes_per_file: int = Field(1024 * KIB, ge=1)  # [B] a long CSV log, a big YAML map
    max_workspace_bytes: int = Field(4096 * KIB, ge=1)  # [B] newest versions; every run copies it
    # Version history (older versions pruned, oldest first, at each save; a file's newest is
    # always kept): hours of autosaves of a node, and twice the workspace, so a data file can be
    # replaced a few times before its old versions go. Counted in the student's disk budget.
    max_versions_per_file: int = Field(200, ge=1)  # every version the page lists
    max_history_bytes_per_workspace: int = Field(8192 * KIB, ge=1)  # [B] all versions, all files
    max_request_body_bytes: int = Field(4096 * KIB, ge=1)  # [B] above every code limit; counted
    # as it arrives (chunked too), for every route, before login
    # Disk: a run leaves its recording, logs and artifacts (up to ~24 MiB of artifacts); runs
    # still on disk count against these budgets, and retention removes old runs' files.
    student_disk_budget_bytes: int = Field(500 * MIB, ge=0)  # [B] per student; 0 = no budget
    lab_disk_budget_bytes: int = Field(20 * GIB, ge=0)  # [B] all runs together; 0 = no budget
    retention_days: float = Field(0.0, ge=0)  # [days] ended runs' files kept; 0 = forever. The
    # instructor can change it at run time (PUT /api/admin/retention), which wins over this.
    retention_sweep_s: float = Field(3600.0, gt=0)  # [s] how often old runs' files are removed
    retry_after_s: int = Field(10, ge=1)  # [s] told to a client that hit a run limit

    # Real robots: CrowBots (ros_lib over WiFi) connect to this TCP port; rosserial_python's
    # 11411 by default; 0 = any free port (tests); -1 = off. It listens on `rosserial_host`,
    # all interfaces by default, whatever the web service's `host`: the robots are on the bench's
    # WiFi while the web service is often behind a proxy on 127.0.0.1, and a default that robots
    # cannot reach (the web host, as before) left benches with robots that never connected.
    # ros_lib has no authentication: a connection from an address no inventory entry has is
    # closed at once (and backed off, server/hardware/rosserial/limits.py), but addresses can
    # be spoofed on a shared network, so name the robots' VLAN/SSID interface here or firewall
    # the port to their subnet (README, "Network isolation for the bench").
    rosserial_port: int = Field(11411, ge=-1, le=65535)
    rosserial_host: str = "0.0.0.0"

    @property
    def rosserial_bind_host(self) -> str:
        return self.rosserial_host

    hardware_gate: bool = True  # a hardware run needs the same code to have passed in simulation
    hardware_slot_s: float = Field(300.0, gt=0)  # [s] longest turn on a robot
    hardware_start_within_s: float = Field(60.0, gt=0)  # [s] a turn not started passes on

    # HTTP connections (uvicorn, h11): a client that holds a connection without finishing a
    # request must not hold it for long; 150 half-sent requests once stayed open forever.
    header_timeout_s: float = Field(10.0, gt=0)  # [s] request line and headers must be in by then
    # A request body, from the end of its headers: whole within body_timeout_s, and after its
    # first body_rate_grace_s at body_min_rate_bytes_s on average (each that many bytes buys a
    # second); else 408 and closed, before any route or login (50 login bodies sent 1 byte
    # every 4 s once stayed open past 72 s).
    body_timeout_s: float = Field(60.0, gt=0)  # [s] the largest body (4 MiB) at 0.6 Mbit/s
    body_min_rate_bytes_s: float = Field(1024.0, gt=0)  # [B/s] 8 kbit/s: any working link
    body_rate_grace_s: float = Field(10.0, gt=0)  # [s] a slow start, as the headers get
    keep_alive_timeout_s: int = Field(5, ge=1)  # [s] idle between requests (uvicorn's default)
    max_header_bytes: int = Field(32 * KIB, ge=1024)  # [B] request line + headers (h11: 16 KiB)

    # The editor's analysis (server/editor): requests analysed at once, each in a sandboxed
    # process of its own, a student's one at a time; 0 turns the editor's help off (its routes
    # say so).
    editor_workers: int = Field(2, ge=0, le=16)

    unsafe_no_sandbox: bool = False  # trusted machines only: student code runs unconfined
    sandbox_pool: int = Field(2, ge=0)  # warm sandbox processes kept ready
    shutdown_grace_s: float = Field(10.0, gt=0)  # [s] runs get this long to stop cleanly

    @property
    def runs_dir(self) -> Path:
        return self.data / "runs"

    @property
    def store_url(self) -> str:
        from server.store.db import sqlite_url

        return self.database_url or sqlite_url(self.data)

    def base_url(self) -> str:
        if self.public_url:
            return self.public_url.rstrip("/")
        host = "127.0.0.1" if self.host in ("0.0.0.0", "::", "") else self.host
        return f"http://{host}:{self.port}"
