"""Version history is capped (issue 33, finding 9: 60 saves of a 1 MB data file grew the
database by 56 MB): a file keeps its newest versions, a workspace its newest bytes, the oldest
go first, a file's newest version never; and the history counts in the student's disk budget.
On SQLite and PostgreSQL alike (the `store` fixture)."""

from __future__ import annotations

from sqlalchemy import text

from server.store import accounts, workspaces
from server.store.accounts import Role
from server.store.db import migrate
from server.store.workspaces import HistoryCaps

MB = 1_000_000


def student(store, name: str) -> str:
    with store.session() as db:
        return accounts.create_user(db, name, Role.STUDENT, f"{name}@example.org").user.id


def kept(store, user_id: str, workspace: str, filename: str) -> list[int]:
    with store.session() as db:
        return sorted(v.version for v in workspaces.versions(db, user_id, workspace, filename))


def test_sixty_saves_of_a_megabyte_keep_what_the_cap_holds(store):
    ada = student(store, "ada")
    caps = HistoryCaps(versions_per_file=200, workspace_bytes=8 * MB)
    for n in range(60):
        with store.session() as db:
            workspaces.save(db, ada, "crowbot", "map.csv", f"{n:03d}" + "x" * (MB - 3), caps)
    with store.session() as db:
        total = workspaces.history_bytes(db, ada)
    assert total <= 8 * MB  # was 60 MB
    assert kept(store, ada, "crowbot", "map.csv") == list(range(53, 61))  # the newest eight
    with store.session() as db:
        assert workspaces.oldest_kept(db, ada, "crowbot", "map.csv") == 53


def test_a_file_keeps_its_newest_versions(store):
    ada = student(store, "ada")
    caps = HistoryCaps(versions_per_file=5, workspace_bytes=8 * MB)
    for n in range(12):
        with store.session() as db:
            workspaces.save(db, ada, "crowbot", "pid.py", f"kp = {n}\n", caps)
    assert kept(store, ada, "crowbot", "pid.py") == [8, 9, 10, 11, 12]
    # Restoring an old version is a save like any other: the numbering goes on.
    with store.session() as db:
        restored = workspaces.save(db, ada, "crowbot", "pid.py", "kp = 8\n", caps)
    assert restored.version == 13
    assert kept(store, ada, "crowbot", "pid.py") == [9, 10, 11, 12, 13]


def test_the_oldest_go_first_across_files_and_no_files_newest_goes(store):
    ada, bob = student(store, "ada"), student(store, "bob")
    caps = HistoryCaps(versions_per_file=200, workspace_bytes=1000)
    with store.session() as db:
        workspaces.save(db, bob, "crowbot", "a.py", "b" * 900, caps)  # another student's
        workspaces.save(db, ada, "crowbot", "old.py", "o" * 400, caps)  # newest of its file
        workspaces.save(db, ada, "crowbot", "a.py", "1" * 300, caps)
        workspaces.save(db, ada, "crowbot", "a.py", "2" * 300, caps)
        workspaces.save(db, ada, "other", "a.py", "z" * 900, caps)  # another workspace
        workspaces.save(db, ada, "crowbot", "a.py", "3" * 300, caps)  # 1300 B: v1 goes
    assert kept(store, ada, "crowbot", "a.py") == [2, 3]
    assert kept(store, ada, "crowbot", "old.py") == [1]
    assert kept(store, bob, "crowbot", "a.py") == [1] and kept(store, ada, "other", "a.py") == [1]
    with store.session() as db:
        # Newest versions alone over the cap: every old one goes, the newest stay.
        workspaces.save(db, ada, "crowbot", "a.py", "4" * 900, caps)
    assert kept(store, ada, "crowbot", "a.py") == [4]
    assert kept(store, ada, "crowbot", "old.py") == [1]
    with store.session() as db:
        assert workspaces.history_bytes(db, ada) == 400 + 900 + 900
        assert workspaces.history_bytes(db) == 400 + 900 + 900 + 900


def test_sizes_are_utf8_bytes_and_old_rows_are_measured_by_the_migration(store):
    ada = student(store, "ada")
    with store.session() as db:
        saved = workspaces.save(db, ada, "crowbot", "é.txt", "é" * 10)  # 2 bytes each
        assert saved.size_bytes == 20
    # A row saved before migration 0008 has no size: the migration computes it.
    with store.engine.begin() as connection:
        connection.execute(text("UPDATE code_versions SET size_bytes = 0"))
        connection.execute(text("UPDATE alembic_version SET version_num = '0007'"))
        connection.execute(text("ALTER TABLE code_versions DROP COLUMN size_bytes"))
        connection.execute(text("DROP TABLE sandbox_leases"))  # 0009's, made again below
    migrate(store.engine)
    with store.session() as db:
        assert workspaces.history_bytes(db, ada) == 20
