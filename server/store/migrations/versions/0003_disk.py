"""disk budgets and retention: each run's size on disk once it ended, when retention removed its
files, and the lab settings an instructor changes at run time (retention)

Revision ID: 0003
Revises: 0002
"""

import sqlalchemy as sa
from alembic import op

revision = "0003"
down_revision = "0002"
branch_labels = None
depends_on = None


def upgrade() -> None:
    op.create_table(
        "lab_settings",
        sa.Column("key", sa.String(length=64), nullable=False),
        sa.Column("value", sa.JSON(), nullable=False),
        sa.Column("updated_at", sa.Float(), nullable=False),
        sa.PrimaryKeyConstraint("key"),
    )
    with op.batch_alter_table("runs") as runs:
        runs.add_column(sa.Column("disk_bytes", sa.BigInteger(), nullable=True))
        runs.add_column(sa.Column("files_removed_at", sa.Float(), nullable=True))


def downgrade() -> None:
    with op.batch_alter_table("runs") as runs:
        runs.drop_column("files_removed_at")
        runs.drop_column("disk_bytes")
    op.drop_table("lab_settings")
