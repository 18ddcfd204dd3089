"""issue 16: the workers of a cluster, each reporting its capacity and what it runs every few
seconds, so a web process can list them and find the runs of one that was lost

Revision ID: 0007
Revises: 0006
"""

import sqlalchemy as sa
from alembic import op

revision = "0007"
down_revision = "0006"
branch_labels = None
depends_on = None


def upgrade() -> None:
    op.create_table(
        "workers",
        sa.Column("id", sa.String(length=128), nullable=False),
        sa.Column("host", sa.String(length=128), nullable=False),
        sa.Column("capacity", sa.Integer(), nullable=False),
        sa.Column("running", sa.Integer(), nullable=False),
        sa.Column("state", sa.String(length=16), nullable=False),
        sa.Column("message", sa.Text(), nullable=False),
        sa.Column("robots", sa.JSON(), nullable=False),
        sa.Column("started_at", sa.Float(), nullable=False),
        sa.Column("last_seen", sa.Float(), nullable=False),
        sa.PrimaryKeyConstraint("id"),
    )
    op.create_index("ix_workers_last_seen", "workers", ["last_seen"])
    op.create_index("ix_runs_worker_id", "runs", ["worker_id"])


def downgrade() -> None:
    op.drop_index("ix_runs_worker_id", table_name="runs")
    op.drop_index("ix_workers_last_seen", table_name="workers")
    op.drop_table("workers")
