"""The store on SQLite and PostgreSQL alike: migrations, accounts and tokens, code versions,
runs and their restart handling."""

from __future__ import annotations

import os
import time

import pytest
from alembic.autogenerate import compare_metadata
from alembic.migration import MigrationContext
from sqlalchemy import select, text

from server.runs.state import RunState
from server.store import accounts, workspaces
from server.store import runs as run_store
from server.store.accounts import Role
from server.store.db import Store, StoreError, migrate
from server.store.models import Base, RunRecord, Session, User


def test_migrations_build_exactly_the_models(store):
    with store.engine.connect() as connection:
        diff = compare_metadata(MigrationContext.configure(connection), Base.metadata)
    assert diff == []
    assert {"users", "sessions", "runs", "code_versions", "courses"} <= set(store.tables())


def test_migrating_again_changes_nothing(store):
    migrate(store.engine)
    with store.engine.connect() as connection:
        assert connection.execute(text("select version_num from alembic_version")).scalar()


def test_tokens_are_stored_hashed_and_renewing_ends_the_old_one(store):
    with store.session() as db:
        made = accounts.create_user(db, "ada", Role.STUDENT, "ada@example.org")
        user_id, token = made.user.id, made.token
    with store.session() as db:
        stored = db.get(User, user_id)
        assert token not in (stored.token_hash, stored.id) and len(stored.token_hash) == 64
        assert accounts.user_by_token(db, token).id == user_id
        session = accounts.create_session(db, stored)
        assert accounts.user_by_session(db, session).id == user_id
        renewed = accounts.renew_token(db, stored)
    with store.session() as db:
        assert accounts.user_by_token(db, token) is None
        assert accounts.user_by_session(db, session) is None  # renewing logs out browsers
        assert accounts.user_by_token(db, renewed.token).id == user_id


def test_disabling_ends_sessions_and_refuses_the_token(store):
    with store.session() as db:
        made = accounts.create_user(db, "bob", Role.STUDENT)
        session = accounts.create_session(db, made.user)
        accounts.set_disabled(db, made.user, True)
    with store.session() as db:
        assert accounts.user_by_token(db, made.token) is None
        assert accounts.user_by_session(db, session) is None
        assert db.scalars(select(Session)).all() == []


def test_an_expired_session_logs_nobody_in(store):
    with store.session() as db:
        made = accounts.create_user(db, "cleo", Role.STUDENT)
        session = accounts.create_session(db, made.user)
        db.get(Session, accounts.hash_token(session)).expires_at = time.time() - 1
    with store.session() as db:
        assert accounts.user_by_session(db, session) is None


def test_code_versions_grow_and_identical_saves_are_one_version(store):
    with store.session() as db:
        user = accounts.create_user(db, "dan", Role.STUDENT).user
        first = workspaces.save(db, user.id, "distance_pid", "pid.py", "a = 1\n")
        same = workspaces.save(db, user.id, "distance_pid", "pid.py", "a = 1\n")
        second = workspaces.save(db, user.id, "distance_pid", "pid.py", "a = 2\n")
        workspaces.save(db, user.id, "distance_pid", "helper.py", "b = 1\n")
        workspaces.save(db, user.id, "crowbot", "pid.py", "other workspace\n")
    assert (first.version, same.version, second.version) == (1, 1, 2)
    with store.session() as db:
        latest = workspaces.latest_files(db, user.id, "distance_pid")
        assert [(v.filename, v.version, v.code) for v in latest] == [
            ("helper.py", 1, "b = 1\n"),
            ("pid.py", 2, "a = 2\n"),
        ]
        assert [v.version for v in workspaces.versions(db, user.id, "distance_pid", "pid.py")] == [
            2,
            1,
        ]
        assert workspaces.get_version(db, user.id, "distance_pid", "pid.py", 1).code == "a = 1\n"
        assert workspaces.get_version(db, user.id, "distance_pid", "pid.py", 3) is None


def _run(user_id: str, run_id: str, state: RunState, created_at: float, **extra) -> RunRecord:
    return RunRecord(
        id=run_id,
        user_id=user_id,
        exercise_id=extra.pop("exercise_id", None),
        robot="crowbot",
        world="wall_approach",
        clock="lockstep",
        duration_s=10.0,
        seed=0,
        state=str(state),
        reason="",
        created_at=created_at,
        code=[{"name": "n", "code": "x = 'é'"}],
        metrics={"collisions": 0, "nested": {"p99_s": 0.01}},
        nodes={},
        checks=[],
        run_dir="/tmp/x",
        **extra,
    )


def test_runs_filter_and_survive_with_their_json(store):
    with store.session() as db:
        ada = accounts.create_user(db, "ada", Role.STUDENT).user.id
        bob = accounts.create_user(db, "bob", Role.STUDENT).user.id
        run_store.add(db, _run(ada, "a1", RunState.FINISHED, 100.0, exercise_id="distance_pid"))
        run_store.add(db, _run(ada, "a2", RunState.FAILED, 200.0))
        run_store.add(db, _run(bob, "b1", RunState.FINISHED, 300.0, exercise_id="distance_pid"))
    with store.session() as db:
        rows, total = run_store.listing(db, run_store.RunFilter(user_id=ada))
        assert ([r.id for r in rows], total) == (["a2", "a1"], 2)
        rows, _ = run_store.listing(db, run_store.RunFilter(exercise_id="distance_pid"))
        assert [r.id for r in rows] == ["b1", "a1"]
        rows, _ = run_store.listing(db, run_store.RunFilter(state="failed"))
        assert [r.id for r in rows] == ["a2"]
        rows, _ = run_store.listing(db, run_store.RunFilter(since=150.0, until=300.0))
        assert [r.id for r in rows] == ["a2"]
        rows, total = run_store.listing(db, run_store.RunFilter(limit=1, offset=1))
        assert ([r.id for r in rows], total) == (["a2"], 3)
        assert run_store.get(db, "a1").metrics == {"collisions": 0, "nested": {"p99_s": 0.01}}
        assert run_store.get(db, "a1").code[0]["code"] == "x = 'é'"


def test_runs_left_active_are_marked_interrupted_at_start(store):
    with store.session() as db:
        ada = accounts.create_user(db, "ada", Role.STUDENT).user.id
        run_store.add(db, _run(ada, "running", RunState.RUNNING, 1.0))
        run_store.add(db, _run(ada, "done", RunState.FINISHED, 2.0))
        assert run_store.active_count(db, ada) == 1
    with store.session() as db:
        assert run_store.mark_interrupted(db) == 1
    with store.session() as db:
        interrupted = run_store.get(db, "running")
        assert interrupted.state == "interrupted"
        assert interrupted.reason == run_store.INTERRUPTED_BY_RESTART
        assert run_store.get(db, "done").state == "finished"
        assert run_store.active_count(db) == 0


def test_a_session_rolls_back_on_error(store):
    with pytest.raises(RuntimeError), store.session() as db:
        accounts.create_user(db, "ghost", Role.STUDENT)
        raise RuntimeError("boom")
    with store.session() as db:
        assert accounts.list_users(db) == []


@pytest.mark.parametrize(
    ("url", "words"),
    [
        ("mysql://root@127.0.0.1/test", "not supported"),
        ("not a url", "not a URL"),
        ("postgresql://nobody@127.0.0.1:1/none", "cannot open the database"),
    ],
)
def test_a_bad_database_url_is_a_sentence(url, words):
    with pytest.raises(StoreError, match=words):
        Store.open(url)


def test_a_sqlite_folder_that_cannot_be_written_names_the_folder_not_the_url(tmp_path):
    # A data folder that cannot be made (its parent is a file): the sentence is about the
    # folder and its owner, never the PostgreSQL advice about users, hosts and ports.
    blocker = tmp_path / "not-a-folder"
    blocker.write_text("")
    folder = blocker / "data"
    with pytest.raises(StoreError) as raised:
        Store.open(f"sqlite:///{folder / 'robodojo.db'}")
    message = str(raised.value)
    assert f"The folder {folder} must exist and be writable" in message
    assert f"chown {os.getuid()}:{os.getgid()}" in message
    assert "user, password" not in message
