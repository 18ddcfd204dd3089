"""A fresh, migrated store per test, on SQLite and on PostgreSQL.

PostgreSQL: the server at ROBODOJO_TEST_POSTGRES_URL (default the machine's local one, trust
auth); each test gets a new database, dropped afterwards. When none is reachable the PostgreSQL
cases are skipped, and the skip reason says so in the test summary.
"""

from __future__ import annotations

import os
import uuid
from collections.abc import Iterator

import pytest

from server.store.db import Store

POSTGRES_URL = os.environ.get(
    "ROBODOJO_TEST_POSTGRES_URL", "postgresql://postgres@127.0.0.1:5432/postgres"
)


def _postgres_admin():
    import psycopg

    url = POSTGRES_URL.replace("postgresql+psycopg://", "postgresql://")
    try:
        return psycopg.connect(url, autocommit=True, connect_timeout=3)
    except psycopg.OperationalError as error:
        pytest.skip(
            f"PostgreSQL is not reachable at {POSTGRES_URL} ({str(error).strip()}); these "
            "store tests ran on SQLite only. Set ROBODOJO_TEST_POSTGRES_URL to test on one."
        )


@pytest.fixture
def postgres_url() -> Iterator[str]:
    admin = _postgres_admin()
    name = f"robodojo_test_{uuid.uuid4().hex[:10]}"
    admin.execute(f'CREATE DATABASE "{name}"')
    base = POSTGRES_URL.rsplit("/", 1)[0]
    try:
        yield f"{base}/{name}"
    finally:
        admin.execute(f'DROP DATABASE IF EXISTS "{name}" WITH (FORCE)')
        admin.close()


@pytest.fixture(params=["sqlite", "postgresql"])
def store_url(request, tmp_path) -> str:
    if request.param == "sqlite":
        return f"sqlite:///{tmp_path / 'robodojo.db'}"
    return request.getfixturevalue("postgres_url")


@pytest.fixture
def store(store_url) -> Iterator[Store]:
    opened = Store.open(store_url)
    yield opened
    opened.close()
