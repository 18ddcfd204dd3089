"""issue 33: the sandbox jobs of a student that are not runs (a launch file being read), so
every web process counts them with the student's runs in one sandbox budget

Revision ID: 0009
Revises: 0008
"""

import sqlalchemy as sa
from alembic import op

revision = "0009"
down_revision = "0008"
branch_labels = None
depends_on = None


def upgrade() -> None:
    op.create_table(
        "sandbox_leases",
        sa.Column("id", sa.String(length=32), nullable=False),
        sa.Column("user_id", sa.String(length=32), nullable=False),
        sa.Column("kind", sa.String(length=32), nullable=False),
        sa.Column("sandboxes", sa.Integer(), nullable=False),
        sa.Column("created_at", sa.Float(), nullable=False),
        sa.Column("expires_at", sa.Float(), nullable=False),
        sa.ForeignKeyConstraint(["user_id"], ["users.id"], ondelete="CASCADE"),
        sa.PrimaryKeyConstraint("id"),
    )
    op.create_index("ix_sandbox_leases_user_id", "sandbox_leases", ["user_id"])
    op.create_index("ix_sandbox_leases_expires_at", "sandbox_leases", ["expires_at"])


def downgrade() -> None:
    op.drop_index("ix_sandbox_leases_expires_at", table_name="sandbox_leases")
    op.drop_index("ix_sandbox_leases_user_id", table_name="sandbox_leases")
    op.drop_table("sandbox_leases")
