"""The FastAPI app: the store opened and migrated, runs left active by the last stop marked
interrupted, a first instructor made (its login link printed, as Jupyter does), the sandbox
launcher and the run service started; on shutdown every run stopped cleanly.

    app = create_app(Settings())      # `robodojo serve` does this and hands it to uvicorn
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
from pathlib import Path

from fastapi import FastAPI, Request
from fastapi.middleware.gzip import GZipMiddleware
from fastapi.responses import FileResponse, HTMLResponse, JSONResponse
from fastapi.staticfiles import StaticFiles

from sandbox.launcher import Launcher
from server.api import errors
from server.api.auth import CsrfGuard
from server.api.http_guards import BodyLimit, SecurityHeaders
from server.api.routes import (
    admin,
    admin_courses,
    admin_exercises,
    admin_robots,
    admin_runs,
    catalog,
    checks,
    comparison,
    editor,
    hardware,
    leaderboards,
    live,
    runs,
    session,
    viz,
    workspaces,
)
from server.api.settings import Settings
from server.api.sockets import OpenSockets
from server.editor.service import EditorService
from server.service import disk
from server.service.runs import RunService
from server.sim.registry import topic_types
from server.store import accounts
from server.store import runs as run_store
from server.store.accounts import Role
from server.store.db import Store
from server.workers.remote_bench import bench_for

log = logging.getLogger("robodojo.api")
# web/ through the server/web_assets link, so a wheel carries the pages inside the package.
WEB_DIR = Path(__file__).resolve().parents[1] / "web_assets"
FIRST_INSTRUCTOR = "instructor"


def bootstrap(store: Store, settings: Settings) -> str | None:
    """The first instructor, on an empty database: returns its login URL (printed once)."""
    with store.session() as db:
        if accounts.instructors_exist(db):
            return None
        made = accounts.create_user(db, FIRST_INSTRUCTOR, Role.INSTRUCTOR)
    return f"{settings.base_url()}/login?token={made.token}"


async def _retention_loop(store: Store, settings: Settings) -> None:
    """At start and then every retention_sweep_s: measure ended runs, remove old runs' files."""
    while True:
        try:
            await asyncio.to_thread(disk.sweep, store, settings)
        except Exception:  # a failed sweep (a locked database) is tried again next time
            log.exception("retention sweep failed")
        await asyncio.sleep(settings.retention_sweep_s)


def create_app(settings: Settings | None = None, launcher: Launcher | None = None) -> FastAPI:
    settings = settings or Settings()

    @contextlib.asynccontextmanager
    async def lifespan(app: FastAPI):
        settings.data.mkdir(parents=True, exist_ok=True)
        store = Store.open(settings.store_url)
        if not settings.redis_url:  # a cluster's runs live on its workers, not in this process
            with store.session() as db:
                interrupted = run_store.mark_interrupted(db)
            if interrupted:
                log.warning("%d run(s) were active when the server stopped: marked interrupted",
                            interrupted)  # fmt: skip
        own_launcher = launcher is None
        run_launcher = launcher or Launcher(
            pool_size=settings.sandbox_pool,
            unsafe_no_sandbox=settings.unsafe_no_sandbox,
            message_types=topic_types(),
        )
        app.state.settings = settings
        app.state.store = store
        app.state.hardware = bench_for(store, settings)  # RemoteBench in a cluster
        app.state.hardware.start()
        # The service listens to the hub (a run past its robot's slot is stopped); the hub
        # knows no service.
        app.state.runs = RunService(store, settings, run_launcher, app.state.hardware)
        # The editor's analysis sandbox starts and warms up in the background (seconds).
        app.state.editor = EditorService(
            settings.max_code_bytes_per_file, settings.editor_workers,
            settings.data / "cache" / "editor", sandboxed=not settings.unsafe_no_sandbox,
        )  # fmt: skip
        app.state.editor.start()
        url = bootstrap(store, settings)
        if url:
            print(f"RoboDojo: log in as the instructor at {url}", flush=True)
            print("  (the token in that link also works as 'Authorization: Bearer' for the "
                  "admin API; keep it secret)", flush=True)  # fmt: skip
        else:
            print(f"RoboDojo: serving at {settings.base_url()}/ (for a new instructor login "
                  "link: robodojo login-url)", flush=True)  # fmt: skip
        sweeper = asyncio.create_task(_retention_loop(store, settings))
        try:
            yield
        finally:
            sweeper.cancel()
            with contextlib.suppress(asyncio.CancelledError):
                await sweeper
            app.state.runs.shutdown()  # robots commanded to zero as their runs end
            app.state.editor.close()
            app.state.hardware.stop()
            if own_launcher:
                run_launcher.close()
            store.close()

    app = FastAPI(
        title="RoboDojo",
        summary="A remote lab for small mobile robots: run Python controllers against "
        "simulated or real robots.",
        version="0.1.0",
        lifespan=lifespan,
    )
    app.state.settings = settings
    app.state.sockets = OpenSockets()  # open websockets by user: disabling a user closes them
    errors.install(app)
    # The student page's bundle is ~500 KiB, ~180 KiB gzipped: it matters on a classroom link.
    app.add_middleware(GZipMiddleware, minimum_size=1024)
    app.add_middleware(CsrfGuard)  # cookie-authenticated state changes from our own origin only

    @app.middleware("http")
    async def refuse_nul(request: Request, call_next):
        if "\x00" in request.url.path or "%00" in request.url.query:
            return JSONResponse(
                status_code=400,
                content={"detail": "the address holds a NUL character (%00); remove it"},
            )
        return await call_next(request)

    # Added last, so outermost: the body is counted before any route, login or gzip sees it,
    # and even its 413 carries the security headers.
    app.add_middleware(BodyLimit, max_bytes=settings.max_request_body_bytes)
    app.add_middleware(SecurityHeaders)

    for module in (session, catalog, workspaces, runs, checks, comparison, live, admin, admin_runs,
                   admin_courses, admin_exercises, admin_robots, hardware, viz,
                   leaderboards, editor):  # fmt: skip
        app.include_router(module.router)

    def page(name: str):
        path = WEB_DIR / name
        if path.is_file():
            return FileResponse(path, headers={"Cache-Control": "no-cache"})
        return HTMLResponse(
            "<!doctype html><title>RoboDojo</title><h1>RoboDojo</h1>"
            "<p>The lab's API is running: see <a href='/docs'>/docs</a>.</p>"
        )

    @app.get("/", include_in_schema=False)
    def student_page():
        return page("index.html")

    @app.get("/admin", include_in_schema=False)
    def instructor_page():
        return page("admin.html")

    app.mount("/static", StaticFiles(directory=WEB_DIR / "static", check_dir=False), name="static")
    # The guide (docs/ built by `python3 -m guide.build` into web/guide/, committed and shipped
    # in the wheel like the bundles): public, as a course's handout is.
    app.mount(
        "/guide",
        StaticFiles(directory=WEB_DIR / "guide", html=True, check_dir=False),
        name="guide",
    )
    return app
