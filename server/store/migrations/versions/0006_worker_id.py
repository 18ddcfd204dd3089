"""issue 16: a run records which worker runs it (host:pid), so a lost worker's runs can be found
and ended ("failed: worker lost"), and the admin page can say where each run is

Revision ID: 0006
Revises: 0005
"""

import sqlalchemy as sa
from alembic import op

revision = "0006"
down_revision = "0005"
branch_labels = None
depends_on = None


def upgrade() -> None:
    with op.batch_alter_table("runs") as runs:
        runs.add_column(sa.Column("worker_id", sa.String(length=128), nullable=True))


def downgrade() -> None:
    with op.batch_alter_table("runs") as runs:
        runs.drop_column("worker_id")
