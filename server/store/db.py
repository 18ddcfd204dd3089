"""Opening the store: an engine for a SQLite file (the embedded default) or a PostgreSQL URL,
with the schema brought up to date by Alembic before anything uses it.

    store = Store.open("sqlite:///robodojo-data/robodojo.db")   # or postgresql://...
    with store.session() as db: ...                              # commits, or rolls back

SQLite serves several threads here (FastAPI's thread pool, run workers): WAL journal so readers
do not wait for a writer, and a busy timeout so two writers queue instead of failing.
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterator
from pathlib import Path

from sqlalchemy import Engine, create_engine, event, inspect, text
from sqlalchemy.engine import make_url
from sqlalchemy.exc import ArgumentError, OperationalError
from sqlalchemy.orm import Session, sessionmaker

from server.store.errors import StoreError

MIGRATIONS_DIR = Path(__file__).resolve().parent / "migrations"
SQLITE_BUSY_TIMEOUT_MS = 10_000  # [ms] a writer waits this long for another before failing
MIGRATION_LOCK = 0x526F626F446F6A6F  # PostgreSQL advisory lock key ("RoboDojo") around migrations
ADMISSION_LOCK = 0x526F626F52756E73  # PostgreSQL advisory lock key ("RoboRuns") around admission
POOL_SIZE = 10  # PostgreSQL connections kept open (FastAPI's thread pool is 40 by default)


def normalise_url(url: str) -> str:
    """`postgresql://` and `postgres://` mean psycopg 3 (the driver we install)."""
    for prefix in ("postgresql://", "postgres://"):
        if url.startswith(prefix):
            return "postgresql+psycopg://" + url[len(prefix) :]
    return url


def sqlite_url(data_dir: str | Path) -> str:
    return f"sqlite:///{Path(data_dir).resolve() / 'robodojo.db'}"


def _sqlite_pragmas(dbapi_connection, _record) -> None:
    cursor = dbapi_connection.cursor()
    cursor.execute("PRAGMA journal_mode=WAL")
    cursor.execute(f"PRAGMA busy_timeout={SQLITE_BUSY_TIMEOUT_MS}")
    cursor.execute("PRAGMA foreign_keys=ON")
    cursor.close()


def create(url: str) -> Engine:
    url = normalise_url(url)
    try:
        parsed = make_url(url)
    except ArgumentError:
        raise StoreError(
            f"database URL '{url}' is not a URL; use sqlite:///path/to/file.db or "
            "postgresql://user:password@host:5432/database"
        ) from None
    if parsed.get_backend_name() == "sqlite":
        if parsed.database:
            Path(parsed.database).parent.mkdir(parents=True, exist_ok=True)
        engine = create_engine(url, connect_args={"check_same_thread": False})
        event.listen(engine, "connect", _sqlite_pragmas)
        return engine
    if parsed.get_backend_name() != "postgresql":
        raise StoreError(
            f"database '{parsed.get_backend_name()}' is not supported; use SQLite (the default) "
            "or PostgreSQL (postgresql://...)"
        )
    return create_engine(url, pool_size=POOL_SIZE, max_overflow=20, pool_pre_ping=True)


def migrate(engine: Engine) -> None:
    """Apply every Alembic migration the database has not seen yet."""
    from alembic import command
    from alembic.config import Config

    config = Config()
    config.set_main_option("script_location", str(MIGRATIONS_DIR))
    with engine.begin() as connection:
        if engine.dialect.name == "postgresql":
            # Several processes of a cluster may start at once on a new database: one migrates,
            # the others wait here (until its transaction ends) and then find nothing to do.
            connection.execute(text("SELECT pg_advisory_xact_lock(:key)"), {"key": MIGRATION_LOCK})
        config.attributes["connection"] = connection
        command.upgrade(config, "head")


def _sqlite_problem(database: str, reason: object) -> str:
    """A SQLite file that cannot be opened: say so, and when its folder is not writable by us
    (the usual cause: a bind-mounted or root-owned data folder), say how to fix that."""
    folder = Path(database).parent
    problem = f"cannot open the SQLite database {database}: {reason}."
    if folder.is_dir() and os.access(folder, os.W_OK | os.X_OK):
        return problem
    uid, gid = os.getuid(), os.getgid()
    return (
        f"{problem} The folder {folder} must exist and be writable by this user (uid {uid}): "
        f"`chown {uid}:{gid} {folder}`, or choose another folder with --data (ROBODOJO_DATA)."
    )


class Store:
    def __init__(self, engine: Engine) -> None:
        self.engine = engine
        self._sessions = sessionmaker(engine, expire_on_commit=False)

    @classmethod
    def open(cls, url: str) -> Store:
        engine = None
        try:
            engine = create(url)
            migrate(engine)
        except (OperationalError, OSError) as error:
            if engine is not None:
                engine.dispose()
            reason = getattr(error, "orig", None) or error
            parsed = make_url(normalise_url(url))
            if parsed.get_backend_name() == "sqlite":
                raise StoreError(_sqlite_problem(parsed.database or "", reason)) from None
            where = parsed.render_as_string(hide_password=True)
            raise StoreError(
                f"cannot open the database at {where}: {reason}. Check that the server "
                "runs and the URL (user, password, host, port, database) is right."
            ) from None
        return cls(engine)

    @contextlib.contextmanager
    def session(self) -> Iterator[Session]:
        session = self._sessions()
        try:
            yield session
            session.commit()
        except BaseException:
            session.rollback()
            raise
        finally:
            session.close()

    @contextlib.contextmanager
    def exclusive_session(self, lock: int = ADMISSION_LOCK) -> Iterator[Session]:
        """A session holding a database-wide write lock from its first statement to its commit,
        for a count-then-insert that two processes must not interleave (run admission: two web
        processes each counting a student's runs before either stored one would let both in).
        PostgreSQL: the transaction-scoped advisory lock `lock`; SQLite: BEGIN IMMEDIATE, the
        database's one write lock (`lock` is moot), waited for up to the busy timeout."""
        with self.session() as session:
            if self.dialect == "postgresql":
                session.execute(text("SELECT pg_advisory_xact_lock(:lock)"), {"lock": lock})
            else:  # Python's sqlite3 begins on the first write; take the write lock now
                session.connection().exec_driver_sql("BEGIN IMMEDIATE")
            yield session

    @property
    def dialect(self) -> str:
        return self.engine.dialect.name

    def tables(self) -> list[str]:
        return sorted(inspect(self.engine).get_table_names())

    def close(self) -> None:
        self.engine.dispose()
