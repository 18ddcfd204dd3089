"""`robodojo serve` and `robodojo login-url`: the lab as a web service.

    robodojo serve                                  # http://127.0.0.1:8000, data in ./robodojo-data
    robodojo serve --port 9000 --database-url postgresql://lab@db/robodojo
    robodojo serve --redis-url redis://queue:6379/0 --database-url postgresql://...  # cluster
    robodojo login-url                              # a new login link for the first instructor

Options override the ROBODOJO_* environment variables, which override the defaults (Settings).
"""

from __future__ import annotations

import argparse
import logging
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from server.api.settings import Settings


def _settings(args: argparse.Namespace) -> Settings:
    # Imported here: pydantic-settings costs ~0.1 s, and `robodojo run` builds this parser too.
    from server.api.settings import Settings

    overrides = {}
    keys = ("host", "port", "data", "database_url", "public_url", "redis_url", "workers")
    for key in (*keys, "rosserial_port", "rosserial_host"):
        value = getattr(args, key, None)
        if value is not None:
            overrides[key] = value
    if getattr(args, "unsafe_no_sandbox", False):
        overrides["unsafe_no_sandbox"] = True
    return Settings(**overrides)


def cmd_serve(args: argparse.Namespace) -> int:
    import uvicorn

    from sandbox.launcher import Launcher
    from server.api.app import create_app
    from server.api.http_guards import BodyPace
    from server.api.http_server import h11_with_timeouts
    from server.api.redaction import install_redaction
    from server.sim.registry import topic_types
    from server.store.db import Store
    from server.workers.choose import local_worker_count

    settings = _settings(args)
    logging.basicConfig(level=logging.INFO, format="%(levelname)s %(name)s: %(message)s")
    # Alembic names each of its plugins at INFO: noise on every start. Migrations still show.
    logging.getLogger("alembic.runtime.plugins").setLevel(logging.WARNING)
    # Fail before uvicorn starts, with our sentence, when the database or sandbox cannot work.
    Store.open(settings.store_url).close()
    # A web process whose runs execute on worker processes keeps no warm sandbox waiting for
    # one (a real robot's run, the one kind it executes itself, starts cold).
    runs_here = not settings.redis_url and local_worker_count(settings) == 0
    launcher = Launcher(
        pool_size=settings.sandbox_pool if runs_here else 0,
        unsafe_no_sandbox=settings.unsafe_no_sandbox,
        message_types=topic_types(),
    )
    try:
        config = uvicorn.Config(
            create_app(settings, launcher),
            host=settings.host,
            port=settings.port,
            log_level="info",
            # h11 (not httptools) for its header size bound and our header and body timeouts.
            http=h11_with_timeouts(
                settings.header_timeout_s,
                BodyPace(
                    timeout_s=settings.body_timeout_s,
                    min_rate_bytes_s=settings.body_min_rate_bytes_s,
                    grace_s=settings.body_rate_grace_s,
                ),
            ),
            h11_max_incomplete_event_size=settings.max_header_bytes,
            timeout_keep_alive=settings.keep_alive_timeout_s,
            ws_max_size=1024 * 1024,  # [B] a websocket command is tiny; a megabyte is abuse
            # Telemetry and the 3D view send small JSON/msgpack at up to 60 Hz; compressing each
            # costs more than it saves on a lab network (viser's big point clouds: ~330 ms).
            ws_per_message_deflate=False,
            timeout_graceful_shutdown=int(settings.shutdown_grace_s) + 5,
        )
        install_redaction()  # uvicorn.Config has just set up its loggers
        server = uvicorn.Server(config)
        server.run()
        if not server.started:
            return 3  # uvicorn.run's exit status when the server could not start (port in use)
    finally:
        launcher.close()
    return 0


def cmd_login_url(args: argparse.Namespace) -> int:
    from server.store import accounts
    from server.store.accounts import Role
    from server.store.db import Store

    settings = _settings(args)
    store = Store.open(settings.store_url)
    try:
        with store.session() as db:
            instructors = [u for u in accounts.list_users(db, Role.INSTRUCTOR) if not u.disabled]
            if args.name:
                instructors = [u for u in instructors if u.name == args.name]
            if not instructors:
                raise ValueError(
                    "no such instructor; start the server once (robodojo serve) to create one"
                )
            made = accounts.renew_token(db, instructors[0])
    finally:
        store.close()
    print(f"{settings.base_url()}/login?token={made.token}")
    return 0


def _common(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--host", default=None, help="address to listen on (default 127.0.0.1)")
    parser.add_argument("--port", type=int, default=None, help="port (default 8000)")
    parser.add_argument("--data", default=None, help="folder for the database and recordings")
    parser.add_argument("--database-url", default=None, help="postgresql://... (default SQLite)")
    parser.add_argument("--public-url", default=None, help="how browsers reach this server")


def add_commands(commands) -> None:
    serve = commands.add_parser("serve", help="start the web lab (API, websockets, pages)")
    _common(serve)
    serve.add_argument(
        "--redis-url",
        default=None,
        help="redis://host:6379/0: queue runs for `robodojo worker` processes (a cluster) "
        "instead of running them here",
    )
    serve.add_argument(
        "--workers",
        type=int,
        default=None,
        help="worker processes that execute runs on this machine (default: one per core; "
        "0: in the web process itself)",
    )
    serve.add_argument(
        "--rosserial-port",
        type=int,
        default=None,
        help="TCP port real CrowBots connect to (default 11411; 0 any free port; -1 off)",
    )
    serve.add_argument(
        "--rosserial-host",
        default=None,
        help="address the rosserial port listens on (default 0.0.0.0, all interfaces, whatever "
        "--host is); name the robots' VLAN/SSID interface or firewall the port: ros_lib has no "
        "authentication, see README 'Network isolation for the bench'",
    )
    serve.add_argument(
        "--unsafe-no-sandbox",
        action="store_true",
        help="DANGER: run student code without bubblewrap (trusted code on a laptop only)",
    )
    serve.set_defaults(func=cmd_serve)
    login = commands.add_parser(
        "login-url", help="print a new login link for an instructor (the old one stops working)"
    )
    _common(login)
    login.add_argument("--name", default=None, help="which instructor (default: the first)")
    login.set_defaults(func=cmd_login_url)
