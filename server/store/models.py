"""The tables the web service keeps: users and their sessions, courses, custom exercises, code
versions and runs. Times are UTC epoch seconds (float): the same on SQLite and PostgreSQL,
compared and sorted as numbers. Ids are random hex strings, so a guessed id finds nothing.

Changing a table means a new Alembic migration in server/store/migrations/versions/; a test
compares these models with the migrated schema.
"""

from __future__ import annotations

from sqlalchemy import (
    JSON,
    BigInteger,
    Boolean,
    Float,
    ForeignKey,
    Index,
    Integer,
    String,
    Text,
    UniqueConstraint,
)
from sqlalchemy.orm import DeclarativeBase, Mapped, mapped_column

ID_LENGTH = 32  # [hex chars] uuid4().hex
HASH_LENGTH = 64  # [hex chars] sha256 of a token


class Base(DeclarativeBase):
    pass


class User(Base):
    __tablename__ = "users"

    id: Mapped[str] = mapped_column(String(ID_LENGTH), primary_key=True)
    name: Mapped[str] = mapped_column(String(120))
    email: Mapped[str | None] = mapped_column(String(254), nullable=True)
    role: Mapped[str] = mapped_column(String(16))  # "student" | "instructor"
    disabled: Mapped[bool] = mapped_column(Boolean, default=False)
    # The invite/API token, hashed: the plain token is shown once, when it is made.
    token_hash: Mapped[str] = mapped_column(String(HASH_LENGTH), unique=True)
    token_created_at: Mapped[float] = mapped_column(Float)
    created_at: Mapped[float] = mapped_column(Float)


class Session(Base):
    """A browser session (the cookie's value, hashed)."""

    __tablename__ = "sessions"

    token_hash: Mapped[str] = mapped_column(String(HASH_LENGTH), primary_key=True)
    user_id: Mapped[str] = mapped_column(ForeignKey("users.id", ondelete="CASCADE"), index=True)
    created_at: Mapped[float] = mapped_column(Float)
    expires_at: Mapped[float] = mapped_column(Float)


class Course(Base):
    __tablename__ = "courses"

    id: Mapped[str] = mapped_column(String(ID_LENGTH), primary_key=True)
    name: Mapped[str] = mapped_column(String(120), unique=True)
    created_at: Mapped[float] = mapped_column(Float)


class Enrolment(Base):
    __tablename__ = "enrolments"

    course_id: Mapped[str] = mapped_column(
        ForeignKey("courses.id", ondelete="CASCADE"), primary_key=True
    )
    user_id: Mapped[str] = mapped_column(
        ForeignKey("users.id", ondelete="CASCADE"), primary_key=True
    )


class CourseExercise(Base):
    __tablename__ = "course_exercises"

    course_id: Mapped[str] = mapped_column(
        ForeignKey("courses.id", ondelete="CASCADE"), primary_key=True
    )
    exercise_id: Mapped[str] = mapped_column(String(64), primary_key=True)


class CustomExercise(Base):
    """An exercise an instructor made: from a registry template, or from scratch (robot, world,
    starter code, duration, checks chosen from the generic metrics, thresholds)."""

    __tablename__ = "custom_exercises"

    id: Mapped[str] = mapped_column(String(64), primary_key=True)
    definition: Mapped[dict] = mapped_column(JSON)
    created_by: Mapped[str | None] = mapped_column(
        ForeignKey("users.id", ondelete="SET NULL"), nullable=True
    )
    created_at: Mapped[float] = mapped_column(Float)
    updated_at: Mapped[float] = mapped_column(Float)


class CodeVersion(Base):
    """One saved version of one file of a student's workspace (a workspace per exercise, or
    per robot for free play)."""

    __tablename__ = "code_versions"
    __table_args__ = (
        UniqueConstraint("user_id", "workspace", "filename", "version"),
        Index("ix_code_versions_file", "user_id", "workspace", "filename"),
    )

    id: Mapped[int] = mapped_column(Integer, primary_key=True, autoincrement=True)
    user_id: Mapped[str] = mapped_column(ForeignKey("users.id", ondelete="CASCADE"))
    workspace: Mapped[str] = mapped_column(String(64))
    filename: Mapped[str] = mapped_column(String(64))
    version: Mapped[int] = mapped_column(Integer)
    code: Mapped[str] = mapped_column(Text)
    created_at: Mapped[float] = mapped_column(Float)
    # [B] the code's UTF-8 size: history caps and disk budgets add these up (store/workspaces.py).
    size_bytes: Mapped[int] = mapped_column(Integer, server_default="0")


class RunRecord(Base):
    __tablename__ = "runs"
    __table_args__ = (Index("ix_runs_user_created", "user_id", "created_at"),)

    id: Mapped[str] = mapped_column(String(ID_LENGTH), primary_key=True)
    user_id: Mapped[str] = mapped_column(ForeignKey("users.id", ondelete="CASCADE"))
    exercise_id: Mapped[str | None] = mapped_column(String(64), nullable=True, index=True)
    robot: Mapped[str] = mapped_column(String(32))
    world: Mapped[str] = mapped_column(String(32))
    clock: Mapped[str] = mapped_column(String(16))
    duration_s: Mapped[float] = mapped_column(Float)
    seed: Mapped[int] = mapped_column(Integer)
    state: Mapped[str] = mapped_column(String(16), index=True)
    reason: Mapped[str] = mapped_column(Text, default="")
    created_at: Mapped[float] = mapped_column(Float, index=True)
    started_at: Mapped[float | None] = mapped_column(Float, nullable=True)
    ended_at: Mapped[float | None] = mapped_column(Float, nullable=True)
    sim_time_s: Mapped[float] = mapped_column(Float, default=0.0)
    wall_s: Mapped[float] = mapped_column(Float, default=0.0)
    code: Mapped[list] = mapped_column(JSON)  # [{"name", "code"}] as submitted
    metrics: Mapped[dict] = mapped_column(JSON, default=dict)  # run metrics
    nodes: Mapped[dict] = mapped_column(JSON, default=dict)  # per node: periods, outcome, ...
    checks: Mapped[list] = mapped_column(JSON, default=list)  # exercise check results
    score: Mapped[float | None] = mapped_column(Float, nullable=True)  # 0..1, exercises only
    run_dir: Mapped[str] = mapped_column(Text)
    hardware: Mapped[str | None] = mapped_column(String(64), nullable=True)  # bench robot name
    # [B] the run directory's size, measured when the run ended (None: not measured yet); the
    # disk budgets add these up instead of walking every directory (server/service/disk.py).
    disk_bytes: Mapped[int | None] = mapped_column(BigInteger, nullable=True)
    files_removed_at: Mapped[float | None] = mapped_column(Float, nullable=True)  # by retention
    # A hardware run: the simulation run of the same code that passed its gate, for the
    # sim-vs-real comparison (server/service/comparison.py). None for simulation runs.
    simulation_run_id: Mapped[str | None] = mapped_column(String(ID_LENGTH), nullable=True)
    # The worker executing the run ("host:pid", issue 16), set when it starts; None before.
    worker_id: Mapped[str | None] = mapped_column(String(128), nullable=True, index=True)


class LabSetting(Base):
    """A setting an instructor changes while the lab runs (retention_days); it wins over the
    ROBODOJO_* default of the same name."""

    __tablename__ = "lab_settings"

    key: Mapped[str] = mapped_column(String(64), primary_key=True)
    value: Mapped[dict] = mapped_column(JSON)  # {"value": ...}
    updated_at: Mapped[float] = mapped_column(Float)


class RobotEntry(Base):
    """A real robot on the lab bench, as the instructor registers it: which kind (a simulated
    robot id whose topics it has), how it connects, and the limits the safety layer applies."""

    __tablename__ = "robots"

    id: Mapped[str] = mapped_column(String(ID_LENGTH), primary_key=True)
    name: Mapped[str] = mapped_column(String(64), unique=True)
    kind: Mapped[str] = mapped_column(String(32))  # "crowbot", "turtlebot"
    transport: Mapped[str] = mapped_column(String(16))  # "rosserial" | "create_oi"
    # rosserial: the robot's IP address (a connection from it is this robot);
    # create_oi: the serial port (/dev/ttyUSB0) and its baud rate.
    address: Mapped[str] = mapped_column(String(255))
    baud: Mapped[int | None] = mapped_column(Integer, nullable=True)
    limits: Mapped[dict] = mapped_column(JSON)  # MotionLimits fields
    watchdog_s: Mapped[float] = mapped_column(Float)
    in_service: Mapped[bool] = mapped_column(Boolean, default=True)
    created_at: Mapped[float] = mapped_column(Float)


class LeaderboardSetting(Base):
    """How an instructor set one exercise's leaderboard in one course. No row: the defaults
    (shown, with pseudonyms, never reset)."""

    __tablename__ = "leaderboards"

    course_id: Mapped[str] = mapped_column(
        ForeignKey("courses.id", ondelete="CASCADE"), primary_key=True
    )
    exercise_id: Mapped[str] = mapped_column(String(64), primary_key=True)
    visible: Mapped[bool] = mapped_column(Boolean, default=True)  # False: students get 404
    names: Mapped[str] = mapped_column(String(16))  # "names" | "pseudonyms"
    # Runs created before this (epoch [s]) do not count; None: never reset.
    reset_at: Mapped[float | None] = mapped_column(Float, nullable=True)
    updated_at: Mapped[float] = mapped_column(Float)


class WorkerRecord(Base):
    """A worker process of the cluster (`robodojo worker`), as it last reported itself. Its
    `last_seen` is renewed every few seconds; one unseen for longer is lost, and its runs end
    "failed: worker lost" (server/store/workers.py)."""

    __tablename__ = "workers"

    id: Mapped[str] = mapped_column(String(128), primary_key=True)  # host:pid
    host: Mapped[str] = mapped_column(String(128))
    capacity: Mapped[int] = mapped_column(Integer)  # runs it takes at once
    running: Mapped[int] = mapped_column(Integer)  # runs it holds now
    state: Mapped[str] = mapped_column(String(16))  # WorkerState
    message: Mapped[str] = mapped_column(Text, default="")  # why it is not "ready", a sentence
    robots: Mapped[list] = mapped_column(JSON, default=list)  # bench robots it holds
    started_at: Mapped[float] = mapped_column(Float)
    last_seen: Mapped[float] = mapped_column(Float, index=True)


class SandboxLease(Base):
    """A sandbox job of a student that is not a run (a launch file being read), held while it
    runs, so every web process counts it in the student's sandbox budget (server/service/
    sandbox_budget.py). A process that died holding one frees it at `expires_at`."""

    __tablename__ = "sandbox_leases"

    id: Mapped[str] = mapped_column(String(ID_LENGTH), primary_key=True)
    user_id: Mapped[str] = mapped_column(ForeignKey("users.id", ondelete="CASCADE"), index=True)
    kind: Mapped[str] = mapped_column(String(32))  # what the job is, as a sentence says it
    sandboxes: Mapped[int] = mapped_column(Integer)  # sandbox processes it holds
    created_at: Mapped[float] = mapped_column(Float)
    expires_at: Mapped[float] = mapped_column(Float, index=True)
